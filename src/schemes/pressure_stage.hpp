#pragma once
// The pressure stage of the saturated v-p_w scheme V3 (method-notes §1.4, §2.4, §5.3): after
// V1's explicit steps have given v* and sigma' at the nodes, solve the storage equation
//   K p^{n+1} = p^n/(Q* dt) - S_w div v* (+ the stabilisation, filter and drained terms)
// by preconditioned conjugate gradient (linear_solvers/pore_pressure.hpp), then correct the velocity
// v^{n+1} = v* - (dt/rho) grad p^{n+1}.
#include <memory>
#include <vector>

#include "bc/pore_pressure_conditions.hpp"
#include "linear_solvers/pore_pressure.hpp"
#include "schemes/face_pressure_coupling.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
class PorePressureStage final : public Stage {
 public:
  /// Registers the node field "pore_pressure" (the model then works with total stresses at
  /// the constraints), resolves the pore-pressure conditions and builds the pressure equation.
  explicit PorePressureStage(StaggeredModel<Dim>& model);

  std::string_view name() const override { return "pore_pressure"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override;
  /// The PCG's warm start (p^{n-1}) and its statistics: a resumed run takes the same
  /// iterations to the same pressures.
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;

  Field<double, 1> pore_pressure() const { return pressure_; }
  /// The stress points' pressure-free half-step velocity (solver.pressure_divergence =
  /// "stress_points"), filled by step 1; empty otherwise.
  FieldView<double, Dim> skeleton_velocity() {
    return skeleton_.empty() ? FieldView<double, Dim>()
                             : FieldView<double, Dim>(skeleton_.data(), m_.stress_points.size(), Dim);
  }
  /// Where step 2 writes tr d^{n+1/2} per node (solver.pressure_divergence = "consistent",
  /// method-notes eq. (2.4.20)); null otherwise.
  double* volumetric_rate() { return volumetric_rate_.empty() ? nullptr : volumetric_rate_.data(); }
  /// D v for the consistent storage rate (method-notes eq. (2.4.20)), from the nodal velocity
  /// as it is now; RecordNodeDivergence runs it before the first step (D v^0; with `initial_only`
  /// nothing once known, e.g. in a resumed run) and after the constraints that follow this stage
  /// (D v^{n+1}, before the velocity filter).
  void record_node_divergence(bool initial_only);
  /// 1/Q*, 1/Pa.
  double inverse_storage() const { return inv_storage_; }

  const PressureSolveStats& stats() const { return solver_->stats(); }
  const PorePressureSolver& solver() const { return *solver_; }
  /// Wall time of the whole stage (divergence, solve, velocity correction), s.
  double seconds() const { return seconds_; }

  /// C c_u / c_d, the Courant number of the undrained P wave (c_u^2 = (lambda + 2G + Q)/rho),
  /// largest over the materials, and the number of boundary nodes that are neither drained nor
  /// held in their normal direction (impermeable faces carrying a prescribed, possibly zero,
  /// total stress). The step is unstable at such faces once that Courant number exceeds
  /// undrained_courant_limit() (docs/VALIDATION.md, Case 16).
  double undrained_courant() const { return undrained_courant_; }
  Index impermeable_stress_face_nodes() const { return impermeable_stress_faces_; }
  /// Those faces are taken implicitly (solver.pressure_faces = "implicit"): the limit is gone.
  bool implicit_faces() const { return !face_coupling_.empty(); }
  /// Nodes whose pressure-filter gradient was fitted to quadratics (truncated supports;
  /// solver.pressure_filter_gradient = "quadratic" or "quadratic_drained"), for summary.json.
  Index filter_fitted_rows() const { return filter_fitted_rows_; }
  /// The explicit face condition's measured limit on C c_u/c_d: 3.5 with the storage rate
  /// "nodes" or "stress_points" (stable at 2.7, 2.9, 3.4; unstable at 3.6), 2.5 with
  /// "consistent" (stable at 2.41 / 2.53, unstable at 2.56 / 2.68 on a 2D sample / 1D column:
  /// docs/VALIDATION.md).
  double undrained_courant_limit() const { return consistent() ? 2.5 : 3.5; }
  /// solver.pressure_faces = "auto" takes the faces implicitly above this C c_u/c_d, a margin
  /// below the limit: 2.5 ("nodes"), 2.0 ("consistent").
  double auto_implicit_courant() const { return consistent() ? 2.0 : 2.5; }
  /// The growth guard's hint when the limit above is exceeded (empty otherwise).
  std::string instability_hint() const;

 private:
  StaggeredModel<Dim>& m_;
  Field<double, 1> pressure_;
  PorePressureConditions conditions_;
  CorrectedOperator<Dim> node_operator_;  // nodes -> nodes: div v*, grad p
  std::vector<double> odd_even_weight_;     // per pair slot of node_operator_: eq. (2.4.19)'s a
  std::vector<double> odd_even_amplitude_;  // a per node, scratch of the step
  FacePressureCoupling<Dim> face_coupling_;  // implicit face condition (empty: none or explicit)
  std::unique_ptr<PorePressureSolver> solver_;
  std::vector<double> p_old_, source_;
  std::vector<double> pressure_gradient_;  // incremental projection: grad p^n / rho (Dim per node)
  std::vector<double> skeleton_;           // pressure-free half-step velocity (Dim per stress point)
  /// Consistent storage rate (eq. (2.4.20)): tr d^{n+1/2} from step 2, and (D v^n)_I, the node
  /// divergence of the velocity this stage left at the last step (invalid before the first).
  std::vector<double> volumetric_rate_, previous_divergence_;
  bool previous_divergence_valid_ = false;
  /// Force-driven rigid bodies (small deformation, method-notes eq. (4.6.3)): per coupled
  /// (body, axis) j, its nodes and their weights a_j = -n A_I (the reaction on the body per unit
  /// p_w), dt/M, the divergence per unit body velocity d_j (per node) and z_j = K^{-1} S_w
  /// (dt/M) d_j; and (I + W^T Z)^{-1} (row-major, j x j).
  struct BodyCoupling {
    std::size_t body = 0;
    int axis = 0;
    double gain = 0.0;  // dt / M, s/kg (per unit thickness)
    std::vector<Index> nodes;
    std::vector<double> weight;
    std::vector<double> divergence, z;
  };
  std::vector<BodyCoupling> bodies_;
  std::vector<double> body_inverse_;
  std::vector<double> body_dv_, body_w_;  // per coupling, scratch of the step
  void couple_bodies();
  void solve_with_bodies();
  bool consistent() const { return m_.setup.fluid.storage_rate == FluidSpec::StorageRate::consistent; }
  /// The node operator's divergence of a field of Dim values per node, summed over runs of rows
  /// (operators/run_sums.hpp), handed to use(i, div) node by node.
  template <class Use>
  void each_node_divergence(const double* field, Use&& use) const;
  double inv_storage_ = 0.0;
  double stabilisation_time_ = 0.0;  // dt (method-notes §2.4) or dt/2 ("stress_points")
  double undrained_courant_ = 0.0;
  Index impermeable_stress_faces_ = 0;
  Index filter_fitted_rows_ = 0;
  double seconds_ = 0.0;
};

/// V3 with the consistent storage rate: the nodal divergence D v of method-notes eq. (2.4.20),
/// before the first step (initial_only: D v^0) and after the constraints that follow the
/// pressure stage (D v^{n+1} for the next step).
template <int Dim>
class RecordNodeDivergence final : public Stage {
 public:
  RecordNodeDivergence(PorePressureStage<Dim>& pressure, bool initial_only)
      : pressure_(pressure), initial_only_(initial_only) {}
  std::string_view name() const override { return initial_only_ ? "storage_rate_start" : "storage_rate_record"; }
  void run(const StepContext& /*context*/) override { pressure_.record_node_divergence(initial_only_); }

 private:
  PorePressureStage<Dim>& pressure_;
  bool initial_only_;
};

}  // namespace rktsph
