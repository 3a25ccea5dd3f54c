#pragma once
// The stages V2 adds to V1's (method-notes §5.2): the neighbour relations and corrected
// operators rebuilt from the current positions at the start of every step.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bodies/contact.hpp"
#include "neighbours/relation.hpp"
#include "operators/free_surface.hpp"
#include "schemes/body_output.hpp"
#include "schemes/moving_operators.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

/// The corrected operators and the difference gradient recomputed from the particles' current
/// positions every step (never frozen), over Verlet lists: relations built with a skin around
/// the support, rebuilt only when some particle has moved half the skin since the last build
/// (so that no pair within the support can be missing). On the fly (solver.operators, the
/// default) the steps evaluate the operators' rows from these lists themselves
/// (MovingOperators); stored, the weights are rebuilt here as plain CSR (moved particles no
/// longer share row geometries). With a `reorder` action (solver.sort = "auto" or
/// "always"), both sets are sorted into the Morton order of their cells just before a search
/// (every one, or once the storage has become disordered), and the action moves the model's
/// and the stages' per-particle tables with them.
template <int Dim>
class RebuildOperators final : public Stage {
 public:
  using ReorderAction = std::function<void(const Reordering&)>;
  explicit RebuildOperators(StaggeredModel<Dim>& model, ReorderAction reorder = {});
  std::string_view name() const override { return "rebuild_operators"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return to_stress_points_.bytes() + to_nodes_.bytes() + constrained_.bytes() + node_neighbours_.bytes() +
           moving_.bytes() + sort_keys_.capacity() * sizeof(std::uint64_t) +
           (reordering_.nodes.capacity() + reordering_.stress_points.capacity()) * sizeof(Index);
  }

  /// Relations rebuilt (neighbour searches), operators recomputed, and the time of each, s.
  long relation_builds() const { return relation_builds_; }
  long operator_builds() const { return operator_builds_; }
  double relation_seconds() const { return relation_seconds_; }
  /// Sorts that changed the order, and the time of the sorting (keys, sort, moving the data,
  /// and the gap measures that decide it), s.
  long sorts() const { return sorts_; }
  double sort_seconds() const { return sort_seconds_; }
  double operator_seconds() const { return operator_seconds_; }
  /// The skin of the Verlet lists, m.
  double skin() const { return skin_; }
  /// The nodes' own Verlet neighbours (within the support plus the skin), for free-surface
  /// detection; empty unless the case detects its free surface.
  const Relation<Dim>& node_neighbours() const { return node_neighbours_; }
  /// The stress points near each node (Verlet), for the surface nodes' difference gradient.
  const Relation<Dim>& stress_points_of_nodes() const { return to_nodes_; }
  /// The candidates of the steps' operator rows and the degenerate-row record (both storages).
  MovingOperators<Dim>& moving_operators() { return moving_; }
  const MovingOperators<Dim>& moving_operators() const { return moving_; }
  /// The degenerate-row record and the Verlet reference survive a resume; the lists are
  /// searched afresh after one, on the checkpoint's order.
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"neighbour_searches", static_cast<double>(relation_builds_)},
            {"neighbour_search_seconds", relation_seconds_},
            {"particle_sorts", static_cast<double>(sorts_)},
            {"particle_sort_seconds", sort_seconds_},
            {"storage_gap_last_search", gap_},
            {"operator_builds", static_cast<double>(operator_builds_)},
            {"operator_build_seconds", operator_seconds_},
            {"verlet_skin", skin_},
            {"degenerate_rows_max", static_cast<double>(moving_.degenerate_max)},
            {"degenerate_rows_first_time", moving_.degenerate_first_time},
            {"regularised_rows_max", static_cast<double>(moving_.regularised_max)},
            {"regularised_rows_first_time", moving_.regularised_first_time},
            {"operators_on_the_fly", moving_.on_the_fly ? 1.0 : 0.0}};
  }

 private:
  /// Search the four relations; new_reference: measure the next trigger from the positions now.
  void build_relations(bool new_reference);
  /// The Morton orders of both sets (neighbours/morton.hpp) into reordering_; false when both
  /// are sorted already.
  bool morton_orders();
  /// Apply reordering_ through the reorder action.
  void apply_sort();
  /// The constrained nodes' positions, in constrained() order (after any reordering).
  void gather_constrained_positions();
  /// The storage's disorder: the mean index gap over the nodes' relation pairs (a node's index
  /// scaled to the stress points' count against its stress point's), as stored or after r.
  double storage_gap(const Reordering* r = nullptr) const;
  /// "auto" sorts once the gap exceeds this multiple of its value after the last sort.
  static constexpr double kResortGap = 2.0;

  StaggeredModel<Dim>& m_;
  ReorderAction reorder_;
  Reordering reordering_;
  std::vector<std::uint64_t> sort_keys_;
  long sorts_ = 0;
  double sort_seconds_ = 0.0;
  double gap_ = -1.0, gap_ref_ = -1.0;  // storage gap at the last search and after the last sort
  bool resumed_ = false;  // the Verlet reference came from a checkpoint
  double skin_;
  exec::ReductionScratch reduction_;  // the Verlet trigger's block sums
  Relation<Dim> to_stress_points_, to_nodes_, constrained_, node_neighbours_;
  std::vector<Vec<Dim>> constrained_positions_;
  std::vector<Vec<Dim>> nodes_at_build_, stress_points_at_build_;
  std::int64_t stress_point_replacements_at_build_ = 0;  // a re-seeded set needs a new search
  long relation_builds_ = 0, operator_builds_ = 0;
  double relation_seconds_ = 0.0, operator_seconds_ = 0.0;
  MovingOperators<Dim> moving_;
};

/// The free surface of the nodes detected on their positions at t^n (method-notes §3.6), after
/// RebuildOperators, and the nodal stress there made traction-free in the local normal frame
/// (§3.7) before the stress points read it. Nodes that a boundary entry selects are never
/// flagged: their conditions are the entry's (and the lattice face's, which they stay on). The
/// flags are a particle field ("free_surface", 1 on the surface) saved in checkpoints, as the
/// next detection's temporal coherence reads them (the first detection has none); "normal"
/// holds the outward normals.
template <int Dim>
class DetectFreeSurface final : public Stage {
 public:
  DetectFreeSurface(StaggeredModel<Dim>& model, const RebuildOperators<Dim>& rebuild);
  std::string_view name() const override { return "free_surface"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return previous_.capacity() + flags_.capacity() + excluded_.capacity() + corners_.capacity() +
           (normals_.capacity() + edges_.capacity()) * sizeof(Vec<Dim>) + scratch_.bytes() + mirrors_.bytes();
  }
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  void reordered(const Reordering& reordering) override;
  /// sigma.n = 0 at the flagged nodes with the normals of the last detection.
  void reapply_traction_free();
  /// Rigid bodies (2D): their contact nodes are never flagged, and a node whose flag only
  /// reflects the support cut by a body (its normal pointing into the body) is unflagged; with
  /// solver.surface_mirrors the nodes beside a body first sum their neighbours' mirror images.
  void set_contact(const RigidContact* contact) { contact_ = contact; }
  /// 1 at the flagged nodes where two faces meet, from the last detection (empty before it).
  const std::vector<std::uint8_t>& corners() const { return corners_; }
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"surface_nodes_last_step", static_cast<double>(surface_nodes_)},
            {"detection_seconds", seconds_},
            {"detection_full_passes", static_cast<double>(scratch_.full_passes)},
            {"detection_partial_passes", static_cast<double>(scratch_.partial_passes)},
            {"unflagged_next_to_bodies_last_step", static_cast<double>(unflagged_by_bodies_)},
            {"mirrored_nodes_last_step", static_cast<double>(mirrored_nodes_)}};
  }

 private:
  StaggeredModel<Dim>& m_;
  const RebuildOperators<Dim>& rebuild_;
  Field<double, 1> flag_field_;
  Field<double, Dim> normal_field_;
  std::vector<std::uint8_t> previous_, flags_, excluded_, fixed_excluded_, corners_;
  std::vector<Vec<Dim>> edges_;  // 3D: each surface node's edge direction, zero off an edge
  const RigidContact* contact_ = nullptr;
  Index unflagged_by_bodies_ = 0;
  /// The mirror planes of the last detection (solver.surface_mirrors) and how many nodes had any.
  void build_mirrors();
  DetectionMirrors<Dim> mirrors_;
  Index mirrored_nodes_ = 0;
  FreeSurfaceScratch<Dim> scratch_;
  std::vector<Vec<Dim>> normals_;
  std::vector<Index> surface_;  // the flagged nodes
  Index surface_nodes_ = 0;
  std::int64_t detections_ = 0;
  double seconds_ = 0.0;
};

/// The traction-free condition again at the end of the step, on the nodal stress at t^{n+1},
/// with the normals found at t^n (the particles have moved by v dt, a fraction of the spacing):
/// the written frames and the next step start from a traction-free surface.
template <int Dim>
class SurfaceTractionFree final : public Stage {
 public:
  explicit SurfaceTractionFree(DetectFreeSurface<Dim>& detect) : detect_(detect) {}
  std::string_view name() const override { return "surface_traction_free"; }
  void run(const StepContext&) override { detect_.reapply_traction_free(); }

 private:
  DetectFreeSurface<Dim>& detect_;
};

/// Rigid bodies in 2D (method-notes §4.5), before the free surface is detected: the bodies'
/// velocities over the step and the contact set from the state at t^n.
class ContactSelect final : public Stage {
 public:
  ContactSelect(StaggeredModel<2>& model, const RebuildOperators<2>& rebuild, std::shared_ptr<RigidContact> contact)
      : m_(model), rebuild_(rebuild), contact_(std::move(contact)) {}
  std::string_view name() const override { return "contact_select"; }
  void run(const StepContext& context) override;
  /// The contact slots move with their nodes (the bodies' state is shared with ContactEnforce).
  void reordered(const Reordering& reordering) override {
    if (!reordering.nodes.empty()) contact_->reorder_nodes(reordering.nodes);
  }

 private:
  StaggeredModel<2>& m_;
  const RebuildOperators<2>& rebuild_;
  std::shared_ptr<RigidContact> contact_;
  std::vector<Index> nodes_;  // the contact nodes of the step
};

/// Rigid bodies after step 2 and the prescribed components: the contact constraints at
/// t^{n+1}, the projections and the reactions. Keeps the bodies' state in checkpoints and
/// writes their rows of bodies.csv.
class ContactEnforce final : public Stage, public BodyOutput {
 public:
  ContactEnforce(StaggeredModel<2>& model, std::shared_ptr<RigidContact> contact)
      : m_(model), contact_(std::move(contact)) {
    // Soil within a node's support past its patch's end, or a lattice condition on it (a
    // symmetry roller): no free corner there (method-notes eq. (4.5.8)).
    contact_->set_free_corner_rule(m_.kernel.support_radius(),
                                   [&c = m_.constraints](Index i) { return c.begin(i) != c.end(i); });
  }
  std::string_view name() const override { return "contact_enforce"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override;
  void save(io::StateArchive& archive, const std::string& prefix) const override { contact_->save(archive, prefix); }
  void load(const io::StateArchive& archive, const std::string& prefix) override { contact_->load(archive, prefix); }
  std::vector<std::pair<std::string, double>> report() const override;
  const RigidContact& contact() const { return *contact_; }
  std::string csv_rows(double t) const override;
  bool has_contact_profile() const override { return true; }
  std::string contact_rows(double t) const override;

 private:
  StaggeredModel<2>& m_;
  std::shared_ptr<RigidContact> contact_;
};

}  // namespace rktsph
