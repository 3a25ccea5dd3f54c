#pragma once
// The stages of the staggered RKT-SPH step (method-notes §5.1, §2.2, §0.3):
//   StressPointHalfStep  step 1: nodes -> stress points, t^n -> t^{n+1/2}
//   NodeFullStep         step 2: stress points -> nodes, t^n -> t^{n+1}, and the displacement
//   ApplyConstraints     prescribed components at t^{n+1}
//   VelocityFilter       the fourth-order velocity filter (method-notes §0.3 item 3)
//   StressFilter         the same filter on the nodal stress (V2, method-notes eq. (2.3.4))
// Viscoplastic sources are integrated by Runge–Kutta inside steps 1 and 2 (ViscoplasticSources).
// The time loop allocates nothing: every work array is sized when a stage is made.
#include <memory>
#include <string_view>
#include <vector>

#include "schemes/motion.hpp"
#include "schemes/moving_operators.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
class HourglassControl;

/// Runge–Kutta integration of the materials' viscoplastic source over an interval (method-notes
/// §2.2), shared by steps 1 and 2: each step records the start stress and the flux rate of its
/// particles here, then integrates.
template <int Dim>
class ViscoplasticSources {
 public:
  static constexpr int NS = kStressComponents<Dim>;
  explicit ViscoplasticSources(StaggeredModel<Dim>& model);

  bool active() const { return model_.materials.any_source; }
  /// Row of particle i: its start stress and its flux stress rate (NS values each).
  double* sigma_start(Index i) { return FieldView<double, NS>(sigma_start_.data(), 0, NS)[i]; }
  double* flux_rate(Index i) { return FieldView<double, NS>(rate_.data(), 0, NS)[i]; }
  /// Advance the source of every particle of `runs` over tau: the stress field ends at the
  /// source-corrected value, the history at its new value (method-notes §2.2, additive or
  /// frozen-flux coupling).
  void integrate(double tau, const SourceRuns& runs, FieldView<double, NS> stress, FieldView<double, 0> history);
  /// The same, and the plastic dissipation of the particles of `volume` (the nodes) added to
  /// dissipation(): V (sigma_end + sigma_trial)/2 : C^-1 : (sigma_trial - sigma_end), the stored
  /// energy the source removed, with sigma_trial = sigma_start + tau R (method-notes eq. (5.1.3)).
  void integrate_dissipating(double tau, const SourceRuns& runs, FieldView<double, NS> stress,
                             FieldView<double, 0> history, const std::vector<double>& volume);
  /// The nodes' plastic dissipation so far, J.
  double dissipation() const { return dissipation_; }
  /// The largest number of RK4 sub-steps one particle needed in one interval so far.
  long max_substeps() const { return stats_.max_substeps; }
  /// Every count of the integrations so far (RK4 sub-steps, backward-Euler particles and their
  /// Newton iterations, method-notes §2.5) and the seconds spent in them.
  const SourceStats& stats() const { return stats_; }
  double seconds() const { return seconds_; }
  /// Saved in checkpoints so that a resumed run reports the whole run's counts.
  void save(io::StateArchive& archive, const std::string& prefix) const;
  void load(const io::StateArchive& archive, const std::string& prefix);
  std::size_t bytes() const { return (sigma_start_.size() + rate_.size()) * sizeof(double); }
  /// Room for `particles` rows (grows only when a set was re-seeded larger than any before).
  void reserve(Index particles) {
    const auto n = static_cast<std::size_t>(particles) * NS;
    if (active() && sigma_start_.size() < n) {
      sigma_start_.resize(n, 0.0);
      rate_.resize(n, 0.0);
    }
  }

 private:
  StaggeredModel<Dim>& model_;
  std::vector<double> sigma_start_, rate_;
  std::vector<SourceStats> run_stats_;
  std::vector<double> run_dissipation_;
  SourceStats stats_;
  double seconds_ = 0.0;
  double dissipation_ = 0.0;
};

/// A stage that owns the viscoplastic sources of its scheme (step 2 of every instantiation), so
/// that the run can report their counts whatever the stage's template arguments.
template <int Dim>
class SourceOwner {
 public:
  virtual ~SourceOwner() = default;
  virtual const ViscoplasticSources<Dim>& sources() const = 0;
  /// The energy a stabilisation of the step removed from the nodes so far, J (V2's hourglass
  /// control, method-notes §2.6; 0 without one).
  virtual double stabilisation_loss() const { return 0.0; }
};

/// The pressure term of step 1 in a dry scheme: none.
struct NoPressureGradient {
  static constexpr bool kActive = false;
};

/// V3 (method-notes §5.3): -grad p^n / rho joins the stress points' half-step acceleration; with
/// `skeleton` set, the pressure-free half-step velocity is kept per stress point as well (the
/// option solver.pressure_divergence = "stress_points").
template <int Dim>
struct PorePressureGradient {
  static constexpr bool kActive = true;
  const double* pressure = nullptr;  // node p_w, Pa
  FieldView<double, Dim> skeleton;   // stress points; empty when not kept
};

/// Step 1: interpolation and gradient of the nodal state at the stress points, half step of
/// the flux and the sources (method-notes §5.1 step 1). Moving particles (V2, §5.2): the
/// Jaumann rotation over the half step, the continuity equation, the positions.
template <int Dim, class PressureTerm = NoPressureGradient, class Motion = FixedParticles>
class StressPointHalfStep final : public Stage {
 public:
  StressPointHalfStep(StaggeredModel<Dim>& model, std::shared_ptr<ViscoplasticSources<Dim>> sources,
                      PressureTerm pressure = {});
  std::string_view name() const override { return "stress_points_half_step"; }
  void run(const StepContext& context) override;
  /// Moving particles: evaluate the operator's rows from `moving`'s candidates in the step
  /// instead of reading the model's stored operator when moving->on_the_fly (method-notes §5.2).
  void set_moving_operators(MovingOperators<Dim>* moving) { moving_ = moving; }

 private:
  StaggeredModel<Dim>& m_;
  std::shared_ptr<ViscoplasticSources<Dim>> sources_;
  PressureTerm pressure_;
  MovingOperators<Dim>* moving_ = nullptr;
};

/// Step 2: gradient of the stress points' state at the nodes, full step of the flux and the
/// sources; the displacement from the stress points' velocity (method-notes §5.1 step 2, §0.3
/// item 8). Moving particles (V2): the Jaumann rotation, the continuity equation, the
/// positions moved with the displacement; the velocity by V1's step 2 or the simple scheme.
template <int Dim, class Motion = FixedParticles, class Velocity = TaylorGalerkinVelocity>
class NodeFullStep final : public Stage, public SourceOwner<Dim> {
 public:
  NodeFullStep(StaggeredModel<Dim>& model, std::shared_ptr<ViscoplasticSources<Dim>> sources);
  std::string_view name() const override { return "nodes_full_step"; }
  void run(const StepContext& context) override;
  const ViscoplasticSources<Dim>& sources() const override { return *sources_; }
  std::size_t scratch_bytes() const override { return sources_->bytes(); }
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  /// Also write the stress points' divergence at t^{n+1/2} per node into `rate` (one value a
  /// node, 1/s): the trace of the corrected velocity gradient that the effective stress
  /// integrates (before fix (a) at prescribed components), for V3's consistent storage equation
  /// (method-notes eq. (2.4.20)). Null: not recorded.
  void record_volumetric_rate(double* rate) { volumetric_rate_ = rate; }
  /// Moving particles: as StressPointHalfStep::set_moving_operators, on the stress points'
  /// geometry of t^n that step 1 kept.
  void set_moving_operators(MovingOperators<Dim>* moving) { moving_ = moving; }
  /// V2's hourglass control (method-notes §2.6) over the nodes' own Verlet pairs, applied after
  /// the nodes' update and before the source is integrated.
  void set_hourglass(std::shared_ptr<HourglassControl<Dim>> control, const Relation<Dim>* pairs) {
    hourglass_ = std::move(control);
    hourglass_pairs_ = pairs;
  }
  const HourglassControl<Dim>* hourglass() const { return hourglass_.get(); }
  std::vector<std::pair<std::string, double>> report() const override;
  double stabilisation_loss() const override { return -(hourglass_kinetic_ + hourglass_strain_); }

 private:
  StaggeredModel<Dim>& m_;
  std::shared_ptr<ViscoplasticSources<Dim>> sources_;
  double* volumetric_rate_ = nullptr;
  MovingOperators<Dim>* moving_ = nullptr;
  std::shared_ptr<HourglassControl<Dim>> hourglass_;
  const Relation<Dim>* hourglass_pairs_ = nullptr;
  // The hourglass control's figures over the run: seconds, energy removed from the nodal
  // velocity (kinetic change, J), its pure dissipation and exchange, the largest decay factor.
  double hourglass_seconds_ = 0.0, hourglass_kinetic_ = 0.0, hourglass_strain_ = 0.0, hourglass_dissipation_ = 0.0,
         hourglass_exchange_ = 0.0, hourglass_theta_ = 0.0;
};

/// The prescribed components at t^{n+1} (method-notes §4.1).
template <int Dim>
class ApplyConstraints final : public Stage {
 public:
  explicit ApplyConstraints(StaggeredModel<Dim>& model) : m_(model) {}
  std::string_view name() const override { return "constraints"; }
  void run(const StepContext& context) override { m_.apply_constraints(context.t + context.dt); }

 private:
  StaggeredModel<Dim>& m_;
};

/// v <- v - eps (I - P_NE P_EN)^2 v (method-notes §0.3 item 3): removes the nodal checkerboard
/// that the stress points cannot see; exact on linear fields.
template <int Dim>
class VelocityFilter final : public Stage {
 public:
  VelocityFilter(StaggeredModel<Dim>& model, double strength);
  std::string_view name() const override { return "velocity_filter"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override { return (at_stress_points_.size() + at_nodes_.size()) * sizeof(double); }
  /// Moving particles (V2): the interpolations of the step, on the fly or stored; on the fly
  /// it asks steps 1 and 2 to keep their rows' weights (MovingOperators::record_interpolation).
  void set_moving_operators(MovingOperators<Dim>* moving) {
    moving_ = moving;
    if (moving_ != nullptr && moving_->on_the_fly) moving_->record_interpolation = true;
  }

 private:
  StaggeredModel<Dim>& m_;
  MovingOperators<Dim>* moving_ = nullptr;
  double strength_;
  std::vector<double> at_stress_points_, at_nodes_;  // Dim values per particle
};

/// sigma <- sigma - eps (I - P_NE P_EN)^2 sigma on the nodal stress (V2, method-notes eq.
/// (2.3.4)): the same fourth-order filter for the nodal stress mode that the stress points
/// cannot see, on the mean stress (default) or every component; exact on linear fields,
/// objective (it commutes with a uniform rotation).
template <int Dim>
class StressFilter final : public Stage {
 public:
  static constexpr int NS = kStressComponents<Dim>;
  StressFilter(StaggeredModel<Dim>& model, double strength, StressFilterPart part);
  std::string_view name() const override { return "stress_filter"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return (at_stress_points_.size() + at_nodes_.size() + mean_.size()) * sizeof(double);
  }
  /// Its time for the log, summary.json and the benchmark.
  std::vector<std::pair<std::string, double>> report() const override { return {{"stress_filter_seconds", seconds_}}; }
  double seconds() const { return seconds_; }
  /// Moving particles (V2): the interpolations of the step, on the fly or stored; on the fly
  /// it asks steps 1 and 2 to keep their rows' weights (MovingOperators::record_interpolation).
  void set_moving_operators(MovingOperators<Dim>* moving) {
    moving_ = moving;
    if (moving_ != nullptr && moving_->on_the_fly) moving_->record_interpolation = true;
  }

 private:
  void resize_scratch();
  void filter();

  StaggeredModel<Dim>& m_;
  MovingOperators<Dim>* moving_ = nullptr;
  double strength_;
  StressFilterPart part_;
  std::vector<double> at_stress_points_, at_nodes_;  // NS values a particle (full), one (mean)
  std::vector<double> mean_;                         // the nodal mean stress (mean), Pa
  double seconds_ = 0.0;
};

}  // namespace rktsph
