#pragma once
// A run of a case: the model (particles, operators, constraints), the scheme made for it by
// name (schemes/registry.hpp) and the time control. step() is the algorithm of one time step
// as written in method-notes §5: the scheme's stages in order, then the step's balance
// (momentum, kinetic energy, a non-finite check), the energy account and the growth guard.
#include <algorithm>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "case/case_setup.hpp"
#include "io/state_archive.hpp"
#include "materials/history_layout.hpp"
#include "schemes/scheme.hpp"
#include "schemes/staggered_model.hpp"
#include "schemes/time_control.hpp"

namespace rktsph {

/// The value of one named history variable per particle (0 where the particle's material does
/// not have it).
class HistoryView {
 public:
  HistoryView(FieldView<const double, 0> values, const HistoryLayout& layout, const std::vector<int>& material,
              int name)
      : values_(values), layout_(&layout), material_(&material), name_(name) {}
  template <std::integral I>
  double operator()(I i) const {
    const int slot = layout_->slot((*material_)[static_cast<std::size_t>(i)], static_cast<std::size_t>(name_));
    return slot < 0 ? 0.0 : values_(i, slot);
  }

 private:
  FieldView<const double, 0> values_;
  const HistoryLayout* layout_;
  const std::vector<int>* material_;
  int name_;
};

template <int Dim>
class Simulation {
 public:
  /// Build the model and the scheme named by setup.version, and set the initial state.
  explicit Simulation(CaseSetup<Dim> setup, exec::Threads policy = {});

  /// Advance one time step t^n -> t^{n+1}. Throws SolverError if the state becomes non-finite
  /// or grows without bound; the state of that step is then lost but earlier output is kept.
  void step();

  double time() const { return clock_.time(); }
  double dt() const { return clock_.dt(); }
  long step_count() const { return clock_.steps(); }
  double cfl() const { return clock_.courant(); }
  double max_wave_speed() const { return clock_.wave_speed(); }
  const TimeControl<Dim>& clock() const { return clock_; }

  const StaggeredModel<Dim>& model() const { return *model_; }
  StaggeredModel<Dim>& model() { return *model_; }
  const Scheme& scheme() const { return *scheme_; }
  const CaseSetup<Dim>& setup() const { return model_->setup; }
  const ParticleSet<Dim>& nodes() const { return model_->nodes; }
  const ParticleSet<Dim>& stress_points() const { return model_->stress_points; }
  /// The mass of both particle sets, kg (2D: per unit thickness); summed nodes first, each set
  /// in index order (the conservation checks compare it with its value at the start).
  double total_mass() const {
    double m = 0.0;
    for (Index i = 0; i < nodes().size(); ++i) m += nodes().mass(i);
    for (Index i = 0; i < stress_points().size(); ++i) m += stress_points().mass(i);
    return m;
  }

  /// Reorder the particle sets with every table the model and the stages keep by particle
  /// index (StaggeredModel::reorder, Stage::reordered): what V2's sort and a resume do.
  void reorder(const Reordering& reordering) {
    model_->reorder(reordering);
    scheme_->reordered(reordering);
  }
  /// How many reorderings of the particles so far (V2 sorts them by cell, method-notes §3.8):
  /// an index taken before one no longer names the same particle; a global id does.
  long reorders() const { return model_->reorders(); }
  /// The indices of the nodes in increasing global id: the order the case made them in (before
  /// any reordering), for comparisons across time by particle.
  std::vector<Index> nodes_by_id() const { return by_id(nodes().global_id); }
  std::vector<Index> stress_points_by_id() const { return by_id(stress_points().global_id); }
  /// The node with global id `id` now (a linear search: for the few nodes followed across a
  /// reordering, e.g. probes); -1 if none.
  Index node_with_id(std::int64_t id) const {
    const auto& ids = nodes().global_id;
    const auto it = std::find(ids.begin(), ids.end(), id);
    return it == ids.end() ? Index{-1} : static_cast<Index>(it - ids.begin());
  }

  // Typed views of the state (particles/field.hpp).
  VectorView<Dim> node_velocity() const { return VectorView<Dim>(nodes().view(model_->fields.velocity)); }
  StressView<Dim> node_stress() const { return StressView<Dim>(nodes().view(model_->fields.stress)); }
  VectorView<Dim> node_displacement() const { return VectorView<Dim>(nodes().view(model_->fields.displacement)); }
  VectorView<Dim> stress_point_velocity() const {
    return VectorView<Dim>(stress_points().view(model_->fields.sp_velocity));
  }
  StressView<Dim> stress_point_stress() const {
    return StressView<Dim>(stress_points().view(model_->fields.sp_stress));
  }
  /// Node pore pressure, Pa (compression positive); empty in a dry scheme.
  std::span<const double> node_pore_pressure() const;
  bool saturated() const { return model_->fields.pore_pressure.valid(); }
  const HistoryLayout& history_layout() const { return model_->materials.history; }
  /// History variable `name` at the nodes (throws SolverError if no material declares it).
  HistoryView node_history(std::string_view name) const;
  HistoryView stress_point_history(std::string_view name) const;

  // Writable state, for tests that seed a mode and watch it.
  FieldView<double, Dim> mutable_node_velocity() { return model_->nodes.view(model_->fields.velocity); }
  FieldView<double, kStressComponents<Dim>> mutable_node_stress() { return model_->nodes.view(model_->fields.stress); }
  std::span<double> mutable_node_pore_pressure();

  /// Energies at the current time (the stored energy is summed here, so call it sparingly).
  EnergyBalance energy() const;

  /// Memory held by the state (particle sets and the stages' work space) and by the operators.
  std::size_t state_bytes() const { return model_->state_bytes() + scheme_->scratch_bytes(); }
  std::size_t operator_bytes() const { return model_->operator_bytes(); }
  std::size_t pairs() const { return model_->pairs(); }
  Index operator_patterns() const { return model_->to_stress_points.patterns() + model_->to_nodes.patterns(); }
  Index degenerate_operator_rows() const { return model_->degenerate_operator_rows(); }
  long max_source_substeps() const { return source_stats().max_substeps; }
  /// Counts of the viscoplastic source's integrations so far (RK4 sub-steps, backward-Euler
  /// particles and Newton iterations, method-notes §2.5), and the seconds spent in them.
  SourceStats source_stats() const;
  double source_seconds() const;

  /// Checkpoints: the whole state a run carries from step to step (every evolving field of
  /// both particle sets, the clock, the stages' own state), and its restoration into a
  /// simulation built from the same case. load_state refuses (InputError) a state whose
  /// particles, scheme or time step differ from this simulation's.
  void save_state(io::StateArchive& archive) const;
  void load_state(const io::StateArchive& archive);

 private:
  static std::vector<Index> by_id(const std::vector<std::int64_t>& ids) {
    std::vector<Index> order(ids.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<Index>(k);
    std::sort(order.begin(), order.end(), [&ids](Index a, Index b) {
      return ids[static_cast<std::size_t>(a)] < ids[static_cast<std::size_t>(b)];
    });
    return order;
  }
  /// time.dt_rule = "current": the length of the step from t (method-notes eq. (4.3.3)).
  void choose_step(double t);
  /// A step from the current state this far below the initial one stops the run.
  static constexpr double kSmallestStepRatio = 1e-3;
  /// The end of step's sums; nodes with |v|^2 > speed_limit2 are counted (none at infinity).
  StepSums<Dim> balance_sums(double speed_limit2 = std::numeric_limits<double>::infinity());
  /// Where a growth shows first, for the growth guard's message: the fastest node, its
  /// neighbours within the kernel's support (nodes and stress points), the nearest node and
  /// whether it is on the detected free surface. Computed only when a run is stopped.
  std::string fastest_node() const;
  /// |v|^2 above which a node moves more than dx in a step of length dt (infinity where the case
  /// fixes the step: time.dt may be meant to outrun the waves).
  double speed_limit2(double dt) const;
  /// Stops the run (SolverError) when `fast` nodes moved more than dx in the step of length dt from t.
  void check_node_speeds(double t, double dt, double fast);
  /// The power of the loads: the boundary tractions and the scheme's extra power (bodies).
  double external_power();

  std::unique_ptr<StaggeredModel<Dim>> model_;
  std::unique_ptr<Scheme> scheme_;
  TimeControl<Dim> clock_;
  exec::ReductionScratch reduction_;
  /// ParticleSet::fingerprint of the nodes and the stress points as made from the case.
  std::uint64_t nodes_made_ = 0, stress_points_made_ = 0;
};

}  // namespace rktsph
