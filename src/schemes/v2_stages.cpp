#include "schemes/v2_stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "io/state_archive.hpp"
#include "neighbours/morton.hpp"
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
RebuildOperators<Dim>::RebuildOperators(StaggeredModel<Dim>& model, ReorderAction reorder)
    : m_(model),
      reorder_(std::move(reorder)),
      skin_(kSkinOverH * model.kernel.h()),
      constrained_positions_(model.constraints.constrained().size()) {
  moving_.on_the_fly = model.setup.operators_on_the_fly;
  moving_.nodes_near_stress_points = &to_stress_points_;
  moving_.stress_points_near_nodes = &to_nodes_;
  const double r = operator_relation_options(model.kernel).radius;
  moving_.r2 = r * r;
}

template <int Dim>
bool RebuildOperators<Dim>::morton_orders() {
  // One grid for both sets: cells of the support's side from the lowest corner of either.
  Vec<Dim> lo = Vec<Dim>::Constant(std::numeric_limits<double>::infinity());
  for (const auto* set : {&m_.nodes.position, &m_.stress_points.position}) {
    for (const Vec<Dim>& x : *set) lo = lo.cwiseMin(x);
  }
  const double cell = m_.kernel.support_radius();
  if (!morton_order<Dim>(m_.nodes.position, m_.nodes.global_id, lo, cell, reordering_.nodes, sort_keys_)) {
    reordering_.nodes.clear();
  }
  if (!morton_order<Dim>(m_.stress_points.position, m_.stress_points.global_id, lo, cell, reordering_.stress_points,
                         sort_keys_)) {
    reordering_.stress_points.clear();
  }
  return !reordering_.empty();
}

template <int Dim>
void RebuildOperators<Dim>::gather_constrained_positions() {
  const auto& which = m_.constraints.constrained();
  for (std::size_t k = 0; k < which.size(); ++k) {
    constrained_positions_[k] = m_.nodes.position[static_cast<std::size_t>(which[k])];
  }
}

template <int Dim>
void RebuildOperators<Dim>::apply_sort() {
  reorder_(reordering_);
  ++sorts_;
}

template <int Dim>
double RebuildOperators<Dim>::storage_gap(const Reordering* r) const {
  // Over the pairs of the nodes' relation (node a, stress point j): |a n_s / n_n - j|, both
  // indices as they are, or as they would be after the reordering r.
  const auto& off = to_nodes_.offsets();
  const auto& src = to_nodes_.indices();
  const auto nn = static_cast<std::size_t>(m_.nodes.size()), ns = static_cast<std::size_t>(m_.stress_points.size());
  if (nn == 0 || src.empty()) return 0.0;
  std::vector<Index> node_at, point_at;
  if (r != nullptr && !r->nodes.empty()) node_at = inverse_order(r->nodes);
  if (r != nullptr && !r->stress_points.empty()) point_at = inverse_order(r->stress_points);
  const double ratio = static_cast<double>(ns) / static_cast<double>(nn);
  double sum = 0.0;
  for (std::size_t a = 0; a < nn; ++a) {
    const double at = ratio * static_cast<double>(node_at.empty() ? static_cast<Index>(a) : node_at[a]);
    for (auto k = static_cast<std::size_t>(off[a]); k < static_cast<std::size_t>(off[a + 1]); ++k) {
      const auto j = static_cast<std::size_t>(src[k]);
      sum += std::abs(at - static_cast<double>(point_at.empty() ? static_cast<Index>(j) : point_at[j]));
    }
  }
  return sum / static_cast<double>(src.size());
}

template <int Dim>
void RebuildOperators<Dim>::build_relations(bool new_reference) {
  const auto t0 = Clock::now();
  RelationOptions rel = operator_relation_options(m_.kernel);
  rel.radius += skin_;
  to_stress_points_.build(m_.stress_points.position, m_.nodes.position, rel, m_.policy);
  // The nodes' candidates are the stress points' transposed (the same pairs, by a counting
  // sort instead of a second search).
  to_nodes_.build_transpose(to_stress_points_, m_.nodes.size());
  RelationOptions diff = difference_gradient_relation_options(m_.kernel);
  diff.radius += skin_;
  constrained_.build(constrained_positions_, m_.stress_points.position, diff, m_.policy);
  if (m_.setup.detect_free_surface || m_.setup.hourglass) {
    RelationOptions own = operator_relation_options(m_.kernel);
    own.radius += skin_;
    node_neighbours_.build(m_.nodes.position, m_.nodes.position, own, m_.policy);
  }
  if (new_reference) {
    nodes_at_build_ = m_.nodes.position;
    stress_points_at_build_ = m_.stress_points.position;
    stress_point_replacements_at_build_ = m_.stress_points.replacements();
  }
  ++relation_builds_;
  relation_seconds_ += since(t0);
}

template <int Dim>
void RebuildOperators<Dim>::run(const StepContext& c) {
  // Any pair's distance changed by at most the sum of two displacements since the last search.
  // A resumed run measures them from the checkpoint's reference positions, so that it searches
  // (and sorts) at the steps the uninterrupted run does.
  // Due once some particle has moved half the skin: counted on the threads (a serial sweep over
  // both sets was a serial part of every step).
  const bool renewed = m_.stress_points.replacements() != stress_point_replacements_at_build_;
  const bool resumed = resumed_;
  resumed_ = false;
  const bool reference = relation_builds_ > 0 || resumed;
  bool moved_half_skin = false;
  if (reference && !renewed) {
    const double half2 = 0.25 * skin_ * skin_;
    auto count_moved = [&](const std::vector<Vec<Dim>>& now, const std::vector<Vec<Dim>>& then) {
      return exec::particle_reduce<1>(m_.policy, static_cast<Index>(then.size()), reduction_,
                                      [&](Index i, double* acc) {
                                        const auto iu = static_cast<std::size_t>(i);
                                        acc[0] += (now[iu] - then[iu]).squaredNorm() >= half2 ? 1.0 : 0.0;
                                      })[0];
    };
    moved_half_skin = count_moved(m_.nodes.position, nodes_at_build_) > 0.0 ||
                      count_moved(m_.stress_points.position, stress_points_at_build_) > 0.0;
  }
  const bool due = !reference || renewed || moved_half_skin;
  // Sorted just before a search, so that the new lists are built on the new order: at every
  // search ("always"), or once the gap measured at the last search has doubled since the last
  // sort ("auto"; the gap of the next lists is not known before the search).
  const auto ts = Clock::now();
  bool sorted = false;
  if (due && reorder_ && (m_.setup.sort == SortSetting::always || (gap_ref_ > 0.0 && gap_ > kResortGap * gap_ref_))) {
    if (morton_orders()) apply_sort(), sorted = true;
  }
  sort_seconds_ += since(ts);
  gather_constrained_positions();
  // After a resume the lists are searched afresh even when no search is due (they are not
  // saved), keeping the checkpoint's order and reference positions.
  if (due || relation_builds_ == 0) build_relations(due);
  if (due && reorder_) {
    const auto tg = Clock::now();
    gap_ = storage_gap();
    if (gap_ref_ < 0.0 && !sorted) {
      // The first search: the order the case made the particles in is kept unless Morton's
      // would do better by the same factor (a lattice's rows do better still; a particle
      // file in no order does not).
      if (morton_orders() && gap_ > kResortGap * storage_gap(&reordering_)) {
        apply_sort();
        sorted = true;
        gather_constrained_positions();
        build_relations(true);
        gap_ = storage_gap();
      }
    }
    if (sorted || gap_ref_ < 0.0) gap_ref_ = gap_;
    sort_seconds_ += since(tg);
  }
  const auto t0 = Clock::now();
  if (moving_.on_the_fly) {
    // The steps evaluate the rows (and count the degenerate ones); the operators the model
    // built at the start (for the initial state) are not needed again.
    if (m_.to_stress_points.rows() > 0) m_.to_stress_points = {};
    if (m_.to_nodes.rows() > 0) m_.to_nodes = {};
  } else {
    rebuild_corrected_operator<Dim>(to_stress_points_, m_.stress_points.position, m_.nodes, m_.kernel,
                                    m_.to_stress_points, m_.policy, m_.setup.gradient_floor);
    rebuild_corrected_operator<Dim>(to_nodes_, m_.nodes.position, m_.stress_points, m_.kernel, m_.to_nodes, m_.policy,
                                    m_.setup.gradient_floor);
  }
  build_difference_gradient_into<Dim>(constrained_, constrained_positions_, m_.stress_points, m_.kernel,
                                      m_.constrained_gradient);
  ++operator_builds_;
  operator_seconds_ += since(t0);
  if (!moving_.on_the_fly) moving_.note_rows(m_.degenerate_operator_rows(), m_.regularised_operator_rows(), c.t);
}

template <int Dim>
void RebuildOperators<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "degenerate_max", moving_.degenerate_max);
  a.put(prefix + "degenerate_first_time", moving_.degenerate_first_time);
  a.put_integer(prefix + "regularised_max", moving_.regularised_max);
  a.put(prefix + "regularised_first_time", moving_.regularised_first_time);
  // The Verlet reference: when the next search is due, and with it the next sort.
  auto flat = [](const std::vector<Vec<Dim>>& x) {
    std::vector<double> out;
    out.reserve(x.size() * Dim);
    for (const auto& v : x) {
      for (int d = 0; d < Dim; ++d) out.push_back(v[d]);
    }
    return out;
  };
  a.put(prefix + "verlet_nodes", flat(nodes_at_build_));
  a.put(prefix + "verlet_stress_points", flat(stress_points_at_build_));
  a.put_integer(prefix + "verlet_replacements", stress_point_replacements_at_build_);
  // What decides the next sort under "auto".
  a.put(prefix + "storage_gap", gap_);
  a.put(prefix + "storage_gap_reference", gap_ref_);
  a.put_integer(prefix + "sorts", sorts_);
}

template <int Dim>
void RebuildOperators<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  moving_.degenerate_max = static_cast<Index>(a.integer(prefix + "degenerate_max"));
  moving_.degenerate_first_time = a.number(prefix + "degenerate_first_time");
  if (a.has(prefix + "regularised_max")) {  // absent from checkpoints written before the floor
    moving_.regularised_max = static_cast<Index>(a.integer(prefix + "regularised_max"));
    moving_.regularised_first_time = a.number(prefix + "regularised_first_time");
  }
  if (!a.has(prefix + "verlet_nodes")) return;  // an older checkpoint: search (and sort) afresh
  if (a.has(prefix + "storage_gap")) {
    gap_ = a.number(prefix + "storage_gap");
    gap_ref_ = a.number(prefix + "storage_gap_reference");
    sorts_ = static_cast<long>(a.integer(prefix + "sorts"));
  }
  auto unflat = [](const std::vector<double>& x, std::vector<Vec<Dim>>& out) {
    out.resize(x.size() / Dim);
    for (std::size_t i = 0; i < out.size(); ++i) {
      for (int d = 0; d < Dim; ++d) out[i][d] = x[i * Dim + static_cast<std::size_t>(d)];
    }
  };
  unflat(a.doubles(prefix + "verlet_nodes"), nodes_at_build_);
  unflat(a.doubles(prefix + "verlet_stress_points"), stress_points_at_build_);
  stress_point_replacements_at_build_ = a.integer(prefix + "verlet_replacements");
  // A reference for sets of other sizes (a re-seeding since) cannot be measured against.
  resumed_ = nodes_at_build_.size() == m_.nodes.position.size() &&
             (stress_points_at_build_.size() == m_.stress_points.position.size() ||
              stress_point_replacements_at_build_ != m_.stress_points.replacements());
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
  fixed_excluded_.assign(nn, 0);
  for (const Index i : m_.constraints.constrained()) fixed_excluded_[static_cast<std::size_t>(i)] = 1;
  excluded_ = fixed_excluded_;
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
  const bool first = previous_.empty();
  ++detections_;
  const std::vector<std::uint8_t>* touching = nullptr;
  if constexpr (Dim == 2) {
    if (contact_ != nullptr) touching = &contact_->in_contact();
  }
  // The last flags, and the nodes never flagged: those of the boundary entries, those in contact
  // with a body, and those without volume (deactivated outside the domain box,
  // schemes/deactivate_stage.hpp: no part of the body). On the threads: the loops over every
  // node would otherwise be a serial part of each step.
  exec::particle_for(m_.policy, static_cast<Index>(nn), [&](Index i) {
    const auto iu = static_cast<std::size_t>(i);
    if (!first) previous_[iu] = flag(iu, 0) != 0.0 ? 1 : 0;
    if (touching != nullptr) excluded_[iu] = fixed_excluded_[iu] | (*touching)[iu];
    if (m_.nodes.volume[iu] == 0.0) excluded_[iu] = 1;
  });
  FreeSurfaceOptions options;
  options.refresh_displacement = m_.setup.surface_refresh * m_.dx();
  const DetectionMirrors<Dim>* mirrors = nullptr;
  if (contact_ != nullptr && m_.setup.surface_mirrors) {
    build_mirrors();
    mirrors = &mirrors_;
  }
  detect_free_surface<Dim>(m_.nodes, rebuild_.node_neighbours(), m_.kernel, options, previous_, excluded_, flags_,
                           normals_, m_.policy, &corners_, &scratch_, mirrors, Dim == 3 ? &edges_ : nullptr);
  unflagged_by_bodies_ = 0;
  if constexpr (Dim == 2) {
    // Next to a body the support is cut by it, not by a free surface: a flag whose normal
    // points into a body within the support, at a node with a neighbour in contact with that
    // body (the soil reaches the body there), is that cut (method-notes §4.5, "Free surface").
    // A face facing a body across a gap has no such neighbour and stays flagged.
    if (contact_ != nullptr) {
      const double range = m_.kernel.support_radius();
      const auto& neighbours = rebuild_.node_neighbours();
      for (std::size_t i = 0; i < nn; ++i) {
        if (flags_[i] == 0) continue;
        const int body = contact_->faces_body(m_.nodes.position[i], normals_[i], range);
        if (body < 0) continue;
        bool touches = false;
        for (const Index j : neighbours.row(static_cast<Index>(i))) {
          const auto ju = static_cast<std::size_t>(j);
          if ((m_.nodes.position[ju] - m_.nodes.position[i]).norm() > range) continue;
          for (int k = 0; k < RigidContact::kMaxContacts; ++k)
            touches = touches || contact_->contact_body(ju, k) == body;
        }
        if (!touches) continue;
        flags_[i] = 0;
        normals_[i].setZero();
        ++unflagged_by_bodies_;
      }
    }
  }
  exec::particle_for(m_.policy, static_cast<Index>(nn), [&](Index i) {
    const auto iu = static_cast<std::size_t>(i);
    flag(iu, 0) = flags_[iu];
    for (int d = 0; d < Dim; ++d) normal(iu, d) = normals_[iu][d];
  });
  surface_.clear();
  for (std::size_t i = 0; i < nn; ++i) {
    if (flags_[i] != 0) surface_.push_back(static_cast<Index>(i));
  }
  surface_nodes_ = static_cast<Index>(surface_.size());
  // Step 2 sees sigma.n = 0 through the difference form (NodeFullStep).
  auto& rows = m_.surface;
  rows.row.assign(nn, -1);
  rows.normal.clear();
  rows.corner.clear();
  rows.edge.clear();
  for (std::size_t k = 0; k < surface_.size(); ++k) {
    const auto i = static_cast<std::size_t>(surface_[k]);
    rows.row[i] = static_cast<Index>(k);
    rows.normal.push_back(normals_[i]);
    rows.corner.push_back(corners_[i]);
    if (!edges_.empty()) rows.edge.push_back(edges_[i]);  // 3D only
  }
  build_difference_gradient_rows<Dim>(rebuild_.stress_points_of_nodes(), m_.nodes.position, surface_, m_.stress_points,
                                      m_.kernel, rows.gradient);
  reapply_traction_free();
  seconds_ += since(t0);
}

template <int Dim>
void DetectFreeSurface<Dim>::build_mirrors() {
  // A node not excluded, in front of a face of a body farther than the contact's keep distance
  // and within the support radius, mirrors across that face when the soil reaches the body near
  // it: a neighbour within the support in contact with that body (a face looking at a body across
  // a gap has none, and keeps its own support). Within the keep distance a node not in contact
  // is taken for one released from the body, whose flag is a true free surface (method-notes
  // §4.5, "Free surface"); images there made thesis Case 10 unstable (docs/VALIDATION.md).
  // Coincident faces (a node above the joint of two collinear segments) count once; at most the
  // two nearest faces (a concave corner).
  mirrored_nodes_ = 0;
  mirrors_.planes.clear();
  const auto nn = static_cast<std::size_t>(m_.nodes.size());
  mirrors_.of_node.assign(nn, {-1, -1});
  if constexpr (Dim == 2) {
    const double range = m_.kernel.support_radius();
    const auto& neighbours = rebuild_.node_neighbours();
    const std::size_t bodies = contact_->bodies().size();
    const double keep = contact_->keep_distance();
    struct Face {
      MirrorPlaneAt<Dim> plane;
      double g;
    };
    constexpr int kMaxFaces = 4;
    for (std::size_t i = 0; i < nn; ++i) {
      if (excluded_[i] != 0) continue;
      const Vec<Dim>& xi = m_.nodes.position[i];
      std::array<Face, kMaxFaces> faces;
      int count = 0;
      for (std::size_t b = 0; b < bodies; ++b) {
        const int from = count;
        contact_->planes_near(b, xi, range, [&](const Vec<2>& p, const Vec<2>& n, double g) {
          if (count < kMaxFaces && g > keep) faces[static_cast<std::size_t>(count++)] = {{p, n}, g};
        });
        if (count == from) continue;
        bool reached = false;
        for (const Index j : neighbours.row(static_cast<Index>(i))) {
          const auto ju = static_cast<std::size_t>(j);
          if (reached) break;
          if ((m_.nodes.position[ju] - xi).squaredNorm() >= range * range) continue;
          for (int k = 0; k < RigidContact::kMaxContacts; ++k)
            reached = reached || contact_->contact_body(ju, k) == static_cast<int>(b);
        }
        if (!reached) count = from;
      }
      if (count == 0) continue;
      for (int f = 1; f < count; ++f) {  // nearest first (a handful: by insertion)
        for (int e = f; e > 0 && faces[static_cast<std::size_t>(e)].g < faces[static_cast<std::size_t>(e - 1)].g; --e)
          std::swap(faces[static_cast<std::size_t>(e)], faces[static_cast<std::size_t>(e - 1)]);
      }
      int kept = 0;
      for (int f = 0; f < count && kept < DetectionMirrors<Dim>::kPerNode; ++f) {
        const MirrorPlaneAt<Dim>& plane = faces[static_cast<std::size_t>(f)].plane;
        bool same = false;
        for (int k = 0; k < kept; ++k) {
          const MirrorPlaneAt<Dim>& other = mirrors_.planes[static_cast<std::size_t>(mirrors_.of_node[i][k])];
          same = same || (plane.normal.dot(other.normal) > 1.0 - 1e-9 &&
                          std::abs((plane.point - other.point).dot(other.normal)) < 1e-9 * range);
        }
        if (same) continue;
        mirrors_.of_node[i][static_cast<std::size_t>(kept++)] = static_cast<std::int32_t>(mirrors_.planes.size());
        mirrors_.planes.push_back(plane);
      }
      ++mirrored_nodes_;
    }
  }
}

template <int Dim>
void DetectFreeSurface<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "detections", detections_);
  a.put(prefix + "corners", corners_);  // node shifting reads them before the next detection
  // The settled interior of the last full pass, so that a resumed run skips the nodes, and
  // evaluates all of them again, at the steps the uninterrupted run does.
  if (scratch_.settled.empty()) return;
  a.put(prefix + "settled", scratch_.settled);
  a.put(prefix + "lambda", scratch_.lambda);
  a.put(prefix + "reference_volume", scratch_.reference_volume);
  std::vector<double> flat;
  flat.reserve(scratch_.reference_position.size() * Dim);
  for (const auto& x : scratch_.reference_position) {
    for (int d = 0; d < Dim; ++d) flat.push_back(x[d]);
  }
  a.put(prefix + "reference_position", std::move(flat));
}

template <int Dim>
void DetectFreeSurface<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  detections_ = a.integer(prefix + "detections");
  if (a.has(prefix + "corners")) corners_ = a.bytes(prefix + "corners");
  scratch_.settled.clear();  // without a saved pass the next detection is a full one
  if (!a.has(prefix + "settled")) return;
  scratch_.settled = a.bytes(prefix + "settled");
  scratch_.lambda = a.doubles(prefix + "lambda");
  scratch_.reference_volume = a.doubles(prefix + "reference_volume");
  const auto& flat = a.doubles(prefix + "reference_position");
  scratch_.reference_position.resize(flat.size() / Dim);
  for (std::size_t i = 0; i < scratch_.reference_position.size(); ++i) {
    for (int d = 0; d < Dim; ++d) scratch_.reference_position[i][d] = flat[i * Dim + static_cast<std::size_t>(d)];
  }
  scratch_.active.clear();
  for (std::size_t i = 0; i < scratch_.settled.size(); ++i) {
    if (scratch_.settled[i] == 0) scratch_.active.push_back(static_cast<Index>(i));
  }
  // A partial pass rewrites the flags and normals of the active nodes only: the others are 0.
  flags_.assign(scratch_.settled.size(), 0);
  normals_.assign(scratch_.settled.size(), Vec<Dim>::Zero());
  if constexpr (Dim == 3) edges_.assign(scratch_.settled.size(), Vec<Dim>::Zero());
}

template <int Dim>
void DetectFreeSurface<Dim>::reordered(const Reordering& r) {
  if (r.nodes.empty()) return;
  // The constraints have been remapped: their nodes are found again.
  std::fill(fixed_excluded_.begin(), fixed_excluded_.end(), 0);
  for (const Index i : m_.constraints.constrained()) fixed_excluded_[static_cast<std::size_t>(i)] = 1;
  permute_rows(excluded_, r.nodes);  // it keeps the deactivated nodes
  permute_rows(corners_, r.nodes);   // node shifting reads them before the next detection
  // flags_, normals_, edges_ and surface_ are not read before the next detection rewrites them (the
  // sort runs before it in the step; a resume detects before the step's end needs them), which
  // is a full pass: the settled interior is forgotten.
  scratch_.settled.clear();
}

template <int Dim>
void DetectFreeSurface<Dim>::reapply_traction_free() {
  auto stress = m_.nodes.view(m_.fields.stress);
  for (const Index i : surface_) {
    const auto iu = static_cast<std::size_t>(i);
    rktsph::make_surface_traction_free<Dim>(normals_[iu], corners_[iu] != 0,
                                            edges_.empty() ? Vec<Dim>::Zero() : edges_[iu], stress[i]);
  }
}

void ContactSelect::run(const StepContext& c) {
  const auto v = std::as_const(m_.nodes).view(m_.fields.velocity);
  const auto s = std::as_const(m_.nodes).view(m_.fields.stress);
  contact_->begin_step(c.t, c.dt, c.damping, m_.nodes.position, v, s);
  // Step 2's rows for the contact nodes (method-notes §4.5): the constrained velocity
  // components in their own gradient with the body's velocity at t^{n+1/2}.
  auto& rows = m_.contact;
  const std::size_t nn = m_.nodes.position.size();
  rows.row.assign(nn, -1);
  rows.normal.clear();
  rows.full.clear();
  rows.velocity.clear();
  nodes_.clear();
  const auto& touching = contact_->in_contact();
  for (std::size_t i = 0; i < nn; ++i) {
    if (touching[i] == 0) continue;
    Vec<2> normal = Vec<2>::Zero(), velocity = Vec<2>::Zero();
    int slots = 0;
    bool full = false;
    for (int k = 0; k < RigidContact::kMaxContacts; ++k) {
      const int b = contact_->contact_body(i, k);
      if (b < 0) continue;
      const auto bu = static_cast<std::size_t>(b);
      const ContactLaw law = contact_->bodies()[bu].spec().law;
      const Vec<2>& n = contact_->contact_normal(i, k);
      const Vec<2>& vb = contact_->velocity_half(bu);
      if (slots == 0) {
        normal = n;
        velocity = vb;
      } else {
        // Two bodies (a corner): both normal components held, the velocity from each body's.
        velocity = velocity.dot(normal) * normal + (vb - vb.dot(normal) * normal);
        full = true;
      }
      full = full || law == ContactLaw::rough || law == ContactLaw::bonded ||
             (law == ContactLaw::coulomb && contact_->slip(i, k) == 0);
      ++slots;
    }
    rows.row[i] = static_cast<Index>(nodes_.size());
    nodes_.push_back(static_cast<Index>(i));
    rows.normal.push_back(normal);
    rows.full.push_back(full ? 1 : 0);
    rows.velocity.push_back(velocity);
  }
  build_difference_gradient_rows<2>(rebuild_.stress_points_of_nodes(), m_.nodes.position, nodes_, m_.stress_points,
                                    m_.kernel, rows.gradient);
}

void ContactEnforce::run(const StepContext& c) {
  contact_->end_step(c.dt, m_.nodes.position, m_.nodes.view(m_.fields.velocity), m_.nodes.view(m_.fields.stress),
                     m_.nodes.view(m_.fields.displacement), m_.stress_points.position);
}

std::size_t ContactEnforce::scratch_bytes() const {
  const std::size_t nn = m_.nodes.position.size();
  // Per node: two slots of body, normal and slip (and their last step), the flag, x^n, the sort row.
  return nn * (RigidContact::kMaxContacts * (2 * sizeof(int) + sizeof(Vec<2>) + 2) + 1 + sizeof(Vec<2>) +
               sizeof(std::pair<double, std::size_t>));
}

std::vector<std::pair<std::string, double>> ContactEnforce::report() const {
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t b = 0; b < contact_->bodies().size(); ++b)
    add_body_report(contact_->bodies()[b].spec().name, contact_->state()[b], out);
  return out;
}

std::string ContactEnforce::csv_rows(double t) const {
  std::string rows;
  for (std::size_t b = 0; b < contact_->bodies().size(); ++b)
    rows += body_csv_row(t, contact_->bodies()[b].spec().name, contact_->state()[b]);
  return rows;
}

std::string ContactEnforce::contact_rows(double t) const {
  std::vector<std::string> names;
  for (const auto& body : contact_->bodies()) names.push_back(body.spec().name);
  return contact_csv_rows(t, names, contact_->profile());
}

template class RebuildOperators<1>;
template class RebuildOperators<2>;
template class RebuildOperators<3>;
template class DetectFreeSurface<1>;
template class DetectFreeSurface<2>;
template class DetectFreeSurface<3>;

}  // namespace rktsph
