#include "schemes/v2_stages.hpp"

#include <algorithm>
#include <chrono>

#include "io/state_archive.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/free_surface.hpp"

namespace rktsph {

namespace {
// The skin of the Verlet lists, in units of h: wider lists cost more pairs to test every step,
// narrower ones more searches (measured on the benchmark block, docs/method-notes.md §3.8).
constexpr double kSkinOverH = 0.3;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

template <int Dim>
RebuildOperators<Dim>::RebuildOperators(StaggeredModel<Dim>& model)
    : m_(model), skin_(kSkinOverH * model.kernel.h()), constrained_positions_(model.constraints.constrained().size()) {}

template <int Dim>
void RebuildOperators<Dim>::build_relations() {
  const auto t0 = Clock::now();
  RelationOptions rel = operator_relation_options(m_.kernel);
  rel.radius += skin_;
  to_stress_points_.build(m_.stress_points.position, m_.nodes.position, rel, m_.policy);
  to_nodes_.build(m_.nodes.position, m_.stress_points.position, rel, m_.policy);
  RelationOptions diff = difference_gradient_relation_options(m_.kernel);
  diff.radius += skin_;
  constrained_.build(constrained_positions_, m_.stress_points.position, diff, m_.policy);
  if (m_.setup.detect_free_surface) {
    RelationOptions own = operator_relation_options(m_.kernel);
    own.radius += skin_;
    node_neighbours_.build(m_.nodes.position, m_.nodes.position, own, m_.policy);
  }
  nodes_at_build_ = m_.nodes.position;
  stress_points_at_build_ = m_.stress_points.position;
  ++relation_builds_;
  relation_seconds_ += since(t0);
}

template <int Dim>
void RebuildOperators<Dim>::run(const StepContext& c) {
  const auto& which = m_.constraints.constrained();
  for (std::size_t k = 0; k < which.size(); ++k) {
    constrained_positions_[k] = m_.nodes.position[static_cast<std::size_t>(which[k])];
  }
  // Any pair's distance changed by at most the sum of two displacements since the last search.
  double moved = 0.0;
  if (relation_builds_ > 0) {
    for (std::size_t i = 0; i < nodes_at_build_.size(); ++i) {
      moved = std::max(moved, (m_.nodes.position[i] - nodes_at_build_[i]).squaredNorm());
    }
    for (std::size_t i = 0; i < stress_points_at_build_.size(); ++i) {
      moved = std::max(moved, (m_.stress_points.position[i] - stress_points_at_build_[i]).squaredNorm());
    }
  }
  if (relation_builds_ == 0 || 2.0 * std::sqrt(moved) >= skin_) build_relations();
  const auto t0 = Clock::now();
  rebuild_corrected_operator<Dim>(to_stress_points_, m_.stress_points.position, m_.nodes, m_.kernel,
                                  m_.to_stress_points, m_.policy);
  rebuild_corrected_operator<Dim>(to_nodes_, m_.nodes.position, m_.stress_points, m_.kernel, m_.to_nodes, m_.policy);
  m_.constrained_gradient =
      build_difference_gradient<Dim>(constrained_, constrained_positions_, m_.stress_points, m_.kernel);
  ++operator_builds_;
  operator_seconds_ += since(t0);
  const Index degenerate = m_.degenerate_operator_rows();
  if (degenerate > 0 && degenerate_first_time_ < 0.0) degenerate_first_time_ = c.t;
  degenerate_max_ = std::max(degenerate_max_, degenerate);
}

template <int Dim>
void RebuildOperators<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "degenerate_max", degenerate_max_);
  a.put(prefix + "degenerate_first_time", degenerate_first_time_);
}

template <int Dim>
void RebuildOperators<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  degenerate_max_ = static_cast<Index>(a.integer(prefix + "degenerate_max"));
  degenerate_first_time_ = a.number(prefix + "degenerate_first_time");
}

template <int Dim>
DetectFreeSurface<Dim>::DetectFreeSurface(StaggeredModel<Dim>& model, const RebuildOperators<Dim>& rebuild)
    : m_(model), rebuild_(rebuild) {
  std::vector<std::string> normal_names;
  for (int d = 0; d < Dim; ++d) normal_names.push_back(std::string("n") + "xyz"[d]);
  flag_field_ = m_.nodes.template add_field<double, 1>("free_surface", {"free_surface"}, kFieldOutput | kFieldEvolving);
  normal_field_ =
      m_.nodes.template add_field<double, Dim>("normal", normal_names, kFieldOutput, Dim, FieldKind::vector);
  const auto nn = static_cast<std::size_t>(m_.nodes.size());
  excluded_.assign(nn, 0);
  for (const Index i : m_.constraints.constrained()) excluded_[static_cast<std::size_t>(i)] = 1;
  previous_.reserve(nn);
  flags_.reserve(nn);
  normals_.reserve(nn);
}

template <int Dim>
void DetectFreeSurface<Dim>::run(const StepContext&) {
  const auto t0 = Clock::now();
  auto flag = m_.nodes.view(flag_field_);
  auto normal = m_.nodes.view(normal_field_);
  const auto nn = static_cast<std::size_t>(m_.nodes.size());
  // The temporal coherence needs a last step: the first detection runs without it.
  previous_.resize(detections_ > 0 ? nn : 0);
  for (std::size_t i = 0; i < previous_.size(); ++i) previous_[i] = flag(i, 0) != 0.0 ? 1 : 0;
  ++detections_;
  detect_free_surface<Dim>(m_.nodes, rebuild_.node_neighbours(), m_.kernel, FreeSurfaceOptions{}, previous_, excluded_,
                           flags_, normals_, m_.policy, &corners_, &scratch_);
  surface_.clear();
  for (std::size_t i = 0; i < nn; ++i) {
    flag(i, 0) = flags_[i];
    for (int d = 0; d < Dim; ++d) normal(i, d) = normals_[i][d];
    if (flags_[i] != 0) surface_.push_back(static_cast<Index>(i));
  }
  surface_nodes_ = static_cast<Index>(surface_.size());
  // Step 2 sees sigma.n = 0 through the difference form (NodeFullStep).
  auto& rows = m_.surface;
  rows.row.assign(nn, -1);
  rows.normal.clear();
  rows.corner.clear();
  for (std::size_t k = 0; k < surface_.size(); ++k) {
    const auto i = static_cast<std::size_t>(surface_[k]);
    rows.row[i] = static_cast<Index>(k);
    rows.normal.push_back(normals_[i]);
    rows.corner.push_back(corners_[i]);
  }
  build_difference_gradient_rows<Dim>(rebuild_.stress_points_of_nodes(), m_.nodes.position, surface_, m_.stress_points,
                                      m_.kernel, rows.gradient);
  reapply_traction_free();
  seconds_ += since(t0);
}

template <int Dim>
void DetectFreeSurface<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "detections", detections_);
}

template <int Dim>
void DetectFreeSurface<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  detections_ = a.integer(prefix + "detections");
}

template <int Dim>
void DetectFreeSurface<Dim>::reapply_traction_free() {
  auto stress = m_.nodes.view(m_.fields.stress);
  for (const Index i : surface_) {
    const auto iu = static_cast<std::size_t>(i);
    rktsph::make_surface_traction_free<Dim>(normals_[iu], corners_[iu] != 0, stress[i]);
  }
}

template class RebuildOperators<1>;
template class RebuildOperators<2>;
template class RebuildOperators<3>;
template class DetectFreeSurface<1>;
template class DetectFreeSurface<2>;
template class DetectFreeSurface<3>;

}  // namespace rktsph
