#include "bodies/plates.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/state_archive.hpp"

namespace rktsph {

namespace {

// The axis a unit vector lies along, or -1.
int axis_of_unit(const Vec<2>& u) {
  for (int d = 0; d < 2; ++d) {
    if (std::abs(std::abs(u[d]) - 1.0) <= 1e-12 && std::abs(u[1 - d]) <= 1e-12) return d;
  }
  return -1;
}

}  // namespace

RigidPlates::RigidPlates(const std::vector<BodySpec>& specs, const std::vector<Vec<2>>& positions,
                         const std::vector<std::uint8_t>& faces, double dx, FunctionValue functions,
                         const std::string& file)
    : functions_(std::move(functions)) {
  const double tol = 1e-6 * dx + 1e-12;
  for (const BodySpec& spec : specs) {
    auto fail = [&](const std::string& why) {
      throw InputError(fmt::format("{}: body '{}': {}", spec.where.empty() ? file : spec.where, spec.name, why));
    };
    if (spec.shape == BodyShape::polyline) {
      fail("a polyline body needs solver.version = \"v2\"; in small deformation a body is a plane or a "
           "segment on a face of the lattice");
    }
    if (spec.law == ContactLaw::coulomb) {
      fail("contact = \"coulomb\" needs solver.version = \"v2\"; in small deformation a body is smooth, rough "
           "or bonded (the contact does not slip or separate)");
    }
    // The contact is permanent here: nothing separates, so a tension or release rule would be
    // silently ignored.
    if (spec.adhesion > 0.0) {
      fail("adhesion needs solver.version = \"v2\"; in small deformation the contact does not separate");
    }
    if (spec.release_on_patch_mean) {
      fail("release needs solver.version = \"v2\"; in small deformation the contact does not separate");
    }
    Plate p;
    p.spec = spec;
    // The normal into the soil: a plane's own, or the left of a segment walked from a to b.
    const Vec<2> normal =
        spec.shape == BodyShape::plane ? spec.normal : body_tangent(spec.points[1] - spec.points[0]) * -1.0;
    p.normal_axis = axis_of_unit(normal.normalized());
    if (p.normal_axis < 0) {
      fail("in small deformation a body must be normal to an axis (it lies on a face of the lattice); "
           "inclined bodies need solver.version = \"v2\"");
    }
    p.normal = Vec<2>::Zero();
    p.normal[p.normal_axis] = normal[p.normal_axis] > 0.0 ? 1.0 : -1.0;
    const int t_axis = 1 - p.normal_axis;
    double lo = -HUGE_VAL, hi = HUGE_VAL;
    if (spec.shape == BodyShape::segment) {
      lo = std::min(spec.points[0][t_axis], spec.points[1][t_axis]);
      hi = std::max(spec.points[0][t_axis], spec.points[1][t_axis]);
    }
    const double line = spec.points[0][p.normal_axis];
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const Vec<2>& x = positions[i];
      if (std::abs(x[p.normal_axis] - line) > tol || x[t_axis] < lo - tol || x[t_axis] > hi + tol) continue;
      // The node's face segment along the body, cut where the soil's face ends and where the
      // body ends (a footing's edge node carries half its segment, as a partial load does).
      double a = x[t_axis] - 0.5 * dx, b = x[t_axis] + 0.5 * dx;
      const std::uint8_t f = faces.empty() ? 0 : faces[i];
      if ((f >> (2 * t_axis)) & 1u) a = x[t_axis];
      if ((f >> (2 * t_axis + 1)) & 1u) b = x[t_axis];
      a = std::max(a, lo);
      b = std::min(b, hi);
      p.nodes.push_back(static_cast<Index>(i));
      p.length.push_back(std::max(0.0, b - a));
    }
    if (p.nodes.empty()) {
      fail(fmt::format("lies on no node: in small deformation a body must lie on a face of the lattice "
                       "(nodes within {:.3g} m of its line {} = {})",
                       tol, kAxisNames[static_cast<std::size_t>(p.normal_axis)], line));
    }
    p.full = spec.law != ContactLaw::smooth;
    for (int d = 0; d < 2; ++d) {
      const auto du = static_cast<std::size_t>(d);
      if (!spec.force_driven[du]) p.state.velocity[d] = spec.velocity[du] * functions_(spec.velocity_function[du], 0.0);
    }
    p.velocity_begin = p.state.velocity;
    p.state.contact_nodes = static_cast<long>(p.nodes.size());
    for (const double l : p.length) p.state.width += l;
    plates_.push_back(std::move(p));
  }
}

bool RigidPlates::any_force() const {
  return std::any_of(plates_.begin(), plates_.end(), [](const Plate& p) { return p.spec.any_force(); });
}

void RigidPlates::measure(ConstFieldView<double, NS> s, const double* pore_pressure) {
  for (Plate& p : plates_) {
    Vec<2> force = Vec<2>::Zero();
    for (std::size_t k = 0; k < p.nodes.size(); ++k) {
      const Index i = p.nodes[k];
      const double pw = pore_pressure != nullptr ? pore_pressure[static_cast<std::size_t>(i)] : 0.0;
      const double sxx = s(i, 0) - pw, syy = s(i, 1) - pw, sxy = s(i, 3);
      // F_R = sum sigma n A, total stress (method-notes eq. (4.6.1)).
      force[0] += (sxx * p.normal[0] + sxy * p.normal[1]) * p.length[k];
      force[1] += (sxy * p.normal[0] + syy * p.normal[1]) * p.length[k];
    }
    p.state.force = force;
  }
}

void RigidPlates::drive(double t, double dt, double damping, ConstFieldView<double, NS> s) {
  // The effective-stress reaction at t^{n+1} (the whole reaction in V1): V2's explicit load
  // control (method-notes eq. (4.5.7)), stable for dt^2 K / M < 4.
  if (any_force()) measure(s, nullptr);
  for (Plate& p : plates_) {
    p.velocity_begin = p.state.velocity;
    for (int d = 0; d < 2; ++d) {
      const auto du = static_cast<std::size_t>(d);
      if (!p.spec.force_driven[du]) {
        p.state.velocity[d] = p.spec.velocity[du] * functions_(p.spec.velocity_function[du], t + dt);
        continue;
      }
      p.applied[d] = p.spec.force[du] * functions_(p.spec.force_function[du], t + 0.5 * dt);
      const double a = (p.applied[d] + p.state.force[d]) / p.spec.mass;
      const double v0 = p.state.velocity[d];
      double v1 = v0 + a * dt;
      if (damping != 0.0) {
        const double decay = -std::expm1(-damping * dt);  // 1 - e^{-c_d dt}
        v1 = v0 - decay * v0 + a * decay / damping;
      }
      p.state.velocity[d] = v1;
    }
  }
}

void RigidPlates::finish(double dt, ConstFieldView<double, NS> s, const double* pore_pressure) {
  measure(s, pore_pressure);
  for (Plate& p : plates_) {
    const Vec<2> mean = 0.5 * (p.velocity_begin + p.state.velocity);
    p.state.offset += dt * mean;
    p.state.work += dt * p.state.force.dot(mean);
  }
}

double RigidPlates::power() const {
  double power = 0.0;
  for (const Plate& p : plates_) power += p.state.force.dot(p.state.velocity);
  return power;
}

void RigidPlates::save(io::StateArchive& a, const std::string& prefix) const {
  std::vector<double> values;
  for (const Plate& p : plates_) {
    for (const double v : {p.state.offset[0], p.state.offset[1], p.state.velocity[0], p.state.velocity[1],
                           p.state.force[0], p.state.force[1], p.state.work}) {
      values.push_back(v);
    }
  }
  a.put(prefix + "plates", std::move(values));
}

void RigidPlates::load(const io::StateArchive& a, const std::string& prefix) {
  const auto& values = a.doubles(prefix + "plates");
  constexpr std::size_t kPer = 7;
  if (values.size() != kPer * plates_.size()) {
    throw InputError(fmt::format("checkpoint: {} values for {} rigid bodies (expected {})", values.size(),
                                 plates_.size(), kPer * plates_.size()));
  }
  for (std::size_t b = 0; b < plates_.size(); ++b) {
    const double* v = values.data() + kPer * b;
    BodyState& st = plates_[b].state;
    st.offset = Vec<2>(v[0], v[1]);
    st.velocity = Vec<2>(v[2], v[3]);
    st.force = Vec<2>(v[4], v[5]);
    st.work = v[6];
    plates_[b].velocity_begin = st.velocity;
  }
}

}  // namespace rktsph
