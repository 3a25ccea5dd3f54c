#include "schemes/shift_stage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "io/state_archive.hpp"

namespace rktsph {

namespace {
// The largest shift, in dx: a regulariser moves the particles a fraction of their spacing.
constexpr double kMaxShiftOverDx = 0.2;
// The node-node correction matrix of eq. (5.2.7) must be this well conditioned (|det|, it is
// the identity on a full support) for a node to be shifted.
constexpr double kMinDeterminant = 1e-3;
}  // namespace

template <int Dim>
ShiftNodes<Dim>::ShiftNodes(StaggeredModel<Dim>& model, RebuildOperators<Dim>& rebuild, const RigidContact* contact,
                            const std::vector<std::uint8_t>* corners)
    : m_(model), rebuild_(rebuild), contact_(contact), corners_(corners) {
  flag_field_ = model.nodes.template find<double, 1>("free_surface");
  const auto nn = static_cast<std::size_t>(model.nodes.size());
  const auto per_node =
      static_cast<std::size_t>(2 * Dim + kStressComponents<Dim> + model.materials.history.stride() + 1);
  shift_.assign(nn, Vec<Dim>::Zero());
  increments_.assign(nn * per_node, 0.0);
  frozen_.assign(nn, 0);
}

template <int Dim>
double ShiftNodes<Dim>::closest_pair() const {
  const auto& rel = rebuild_.node_neighbours();
  const auto& x = m_.nodes.position;
  double best = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < rel.rows(); ++i) {
    for (const Index j : rel.row(i)) {
      if (j <= i) continue;
      best = std::min(best, (x[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(j)]).squaredNorm());
    }
  }
  return std::sqrt(best);
}

template <int Dim>
void ShiftNodes<Dim>::run(const StepContext& c) {
  ++steps_since_;
  if (steps_since_ < m_.setup.shift_interval) return;
  // Not before the free surface has been detected once: its nodes must keep their normal place.
  if (corners_ == nullptr || corners_->size() != static_cast<std::size_t>(m_.nodes.size())) return;
  if (m_.setup.shift == ShiftSetting::automatic) {
    closest_ = closest_pair();
    if (closest_ >= m_.setup.shift_distance * m_.dx()) {
      steps_since_ = 0;  // checked: the next check in shift_interval steps
      return;
    }
  }
  shift(c);
  steps_since_ = 0;
}

template <int Dim>
void ShiftNodes<Dim>::shift(const StepContext& c) {
  constexpr int NS = kStressComponents<Dim>;
  const auto& rel = rebuild_.node_neighbours();
  ParticleSet<Dim>& nodes = m_.nodes;
  const auto& x = nodes.position;
  const Index nn = nodes.size();
  const double r2 = m_.kernel.support_radius() * m_.kernel.support_radius();
  const double strength = m_.setup.shift_strength, cap = kMaxShiftOverDx * m_.dx();
  const auto flags = std::as_const(nodes).view(flag_field_);
  // Nodes held by a boundary entry keep their place.
  std::fill(frozen_.begin(), frozen_.end(), 0);
  for (const Index i : m_.constraints.constrained()) frozen_[static_cast<std::size_t>(i)] = 1;
  const auto v = std::as_const(nodes).view(m_.fields.velocity);
  const auto s = std::as_const(nodes).view(m_.fields.stress);
  const auto k = std::as_const(nodes).view(m_.fields.history);
  const auto u = std::as_const(nodes).view(m_.fields.displacement);
  const int nh = k.components();
  const int per_node = 2 * Dim + NS + nh + 1;
  // The fields of node j, in the order of the increments.
  auto field = [&](Index j, int f) {
    if (f < Dim) return v(j, f);
    f -= Dim;
    if (f < NS) return s(j, f);
    f -= NS;
    if (f < nh) return k(j, f);
    f -= nh;
    if (f < Dim) return u(j, f);
    return nodes.density[static_cast<std::size_t>(j)];
  };
  exec::particle_for(m_.policy, nn, [&](Index i) {
    const auto iu = static_cast<std::size_t>(i);
    shift_[iu].setZero();
    double* inc = increments_.data() + iu * static_cast<std::size_t>(per_node);
    for (int f = 0; f < per_node; ++f) inc[f] = 0.0;
    if (frozen_[iu] != 0) return;
    // Eq. (5.2.5): the inverse-square repulsion of the neighbours within the support (Xu et al.
    // 2009), sum_j x_ij / r_ij^3, with the mean neighbour distance rbar; and eq. (5.2.7)'s
    // correction matrix M_i = sum_j V_j grad_i W_ij (x) (x_j - x_i).
    Vec<Dim> push = Vec<Dim>::Zero();
    double rbar = 0.0;
    int neighbours = 0;
    // Whether the support reaches the free surface or a held node (where it is cut), and the
    // nearest node in contact with a body within it (the body's normal holds there).
    bool cut = flags(i, 0) != 0.0;
    Index contact_node = -1;
    double contact_r2 = r2;
    if constexpr (Dim == 2) {
      if (contact_ != nullptr && contact_->in_contact()[iu] != 0) {
        contact_node = i;
        contact_r2 = 0.0;
      }
    }
    Eigen::Matrix<double, Dim, Dim> M = Eigen::Matrix<double, Dim, Dim>::Zero();
    for (const Index j : rel.row(i)) {
      if (j == i) continue;
      const Vec<Dim> x_ij = x[iu] - x[static_cast<std::size_t>(j)];
      const double q2 = x_ij.squaredNorm();
      if (q2 >= r2) continue;
      const double r = std::sqrt(q2);
      if (r > 0.0) push += x_ij / (q2 * r);
      const auto ju = static_cast<std::size_t>(j);
      cut = cut || flags(j, 0) != 0.0 || frozen_[ju] != 0;
      if constexpr (Dim == 2) {
        if (q2 < contact_r2 && contact_ != nullptr && contact_->in_contact()[ju] != 0) {
          contact_node = j;
          contact_r2 = q2;
        }
      }
      rbar += r;
      ++neighbours;
      const Vec<Dim> gw = nodes.volume[static_cast<std::size_t>(j)] * m_.kernel.gradient(x_ij);
      M -= gw * x_ij.transpose();
    }
    if (neighbours == 0 || !(std::abs(M.determinant()) > kMinDeterminant)) return;
    rbar /= neighbours;
    // Where the support is cut by the free surface or a held face, the missing neighbours
    // beyond it would push the nodes across it (and at corners along the other face): they stay.
    if (cut) return;
    // Eq. (5.2.6): beta rbar^2 times the push, capped.
    Vec<Dim> dr = strength * rbar * rbar * push;
    if constexpr (Dim == 2) {
      // On a body and within a support of one: along the body only (its normal removed), so that
      // the cut support does not push the nodes onto it; between two bodies (a corner): stays.
      if (contact_node >= 0) {
        const auto cu = static_cast<std::size_t>(contact_node);
        int slots = 0;
        for (int slot = 0; slot < RigidContact::kMaxContacts; ++slot) {
          if (contact_->contact_body(cu, slot) < 0) continue;
          const Vec<2>& n = contact_->contact_normal(cu, slot);
          dr -= dr.dot(n) * n;
          ++slots;
        }
        if (slots > 1) return;
      }
    }
    const double len = dr.norm();
    if (len > cap) dr *= cap / len;
    if (len == 0.0) return;
    shift_[iu] = dr;
    // Eq. (5.2.7): every field carried to the new position to first order with the corrected
    // node-node gradient, from the values before the shift.
    const Eigen::Matrix<double, Dim, Dim> Minv = M.inverse();
    for (const Index j : rel.row(i)) {
      if (j == i) continue;
      const Vec<Dim> x_ij = x[iu] - x[static_cast<std::size_t>(j)];
      if (x_ij.squaredNorm() >= r2) continue;
      // (grad phi) . dr = sum_j V_j (phi_j - phi_i) (M^-1 grad W_ij) . dr
      const double w = (Minv * (nodes.volume[static_cast<std::size_t>(j)] * m_.kernel.gradient(x_ij))).dot(dr);
      for (int f = 0; f < per_node; ++f) inc[f] += w * (field(j, f) - field(i, f));
    }
  });
  // Apply, after every increment was taken from the fields before the shift.
  auto vw = nodes.view(m_.fields.velocity);
  auto sw = nodes.view(m_.fields.stress);
  auto kw = nodes.view(m_.fields.history);
  auto uw = nodes.view(m_.fields.displacement);
  double largest = 0.0;
  for (Index i = 0; i < nn; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    if (shift_[iu].squaredNorm() == 0.0) continue;
    largest = std::max(largest, shift_[iu].norm());
    const double* inc = increments_.data() + iu * static_cast<std::size_t>(per_node);
    const double mass = nodes.mass(i);
    int f = 0;
    for (int d = 0; d < Dim; ++d) vw(i, d) += inc[f++];
    for (int q = 0; q < NS; ++q) sw(i, q) += inc[f++];
    for (int q = 0; q < nh; ++q) kw(i, q) += inc[f++];
    for (int d = 0; d < Dim; ++d) uw(i, d) += inc[f++];
    nodes.density[iu] += inc[f];
    nodes.volume[iu] = mass / nodes.density[iu];
    nodes.position[iu] += shift_[iu];
  }
  largest_ = std::max(largest_, largest);
  ++shifts_;
  if (first_time_ < 0.0) first_time_ = c.t;
  // The operators of the step on the shifted positions (the Verlet lists searched again if the
  // shift took a pair past the skin).
  rebuild_.run(c);
}

template <int Dim>
void ShiftNodes<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "shifts", shifts_);
  a.put_integer(prefix + "steps_since", steps_since_);
  a.put(prefix + "first_time", first_time_);
  a.put(prefix + "largest", largest_);
  a.put(prefix + "closest", closest_);
}

template <int Dim>
void ShiftNodes<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  shifts_ = static_cast<long>(a.integer(prefix + "shifts"));
  steps_since_ = static_cast<long>(a.integer(prefix + "steps_since"));
  first_time_ = a.number(prefix + "first_time");
  largest_ = a.number(prefix + "largest");
  closest_ = a.number(prefix + "closest");
}

template class ShiftNodes<2>;
template class ShiftNodes<3>;

}  // namespace rktsph
