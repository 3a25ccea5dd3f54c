#pragma once
// V1: the staggered Runge–Kutta Taylor SPH solver for dry soil in small deformation
// (METHOD.md §2.1–2.2, §5.1, with the corrections of §0.3).
//
// Two particle sets: nodes hold v, sigma, kappa at t^n; elements hold the half-step state at
// t^{n+1/2}. Step 1 advances elements from nodal values and gradients over dt/2; step 2
// advances nodes from element gradients over dt. Sources (body force, damping, viscoplastic
// relaxation) are integrated by Runge–Kutta and added to the flux increment (§2.2).
// Particles do not move: every operator is built once, and the time loop allocates nothing.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "case/case_setup.hpp"
#include "core/kernel.hpp"
#include "geometry/particles.hpp"
#include "operators/corrected_operator.hpp"
#include "solvers/pore_pressure.hpp"

namespace rktsph {

/// One prescribed component at a node: the velocity along an axis (component < Dim) or a
/// stress slot (component = Dim + slot), scaled by a time function.
struct NodalConstraint {
  int component = 0;
  double value = 0.0;
  int function = -1;
};

struct EnergyBalance {
  double kinetic = 0.0;         // J (per unit thickness in 2D, per unit area in 1D)
  double strain = 0.0;          // elastic strain energy 1/2 sigma : C^-1 : sigma, J
  double external_work = 0.0;   // work of boundary tractions and body forces since t = 0, J
  double damping_loss = 0.0;    // energy removed by the velocity damping, J
  double initial_strain = 0.0;  // strain energy of the initial state, J
  /// kinetic + strain - initial strain - external work + damping loss (zero if conserved)
  double imbalance() const { return kinetic + strain - initial_strain - external_work + damping_loss; }
};

template <int Dim>
class StaggeredSolver {
 public:
  static constexpr int NS = kStressComponents<Dim>;
  static constexpr int NV = kStateComponents<Dim>;

  /// Builds particles, operators, boundary conditions and the initial state. Takes the
  /// materials out of the setup.
  explicit StaggeredSolver(CaseSetup<Dim>& setup);

  /// Advance one time step t^n -> t^{n+1}. Throws SolverError if the state becomes
  /// non-finite; the state of the previous step is then lost but earlier output is kept.
  void step();

  double time() const { return time_; }
  double dt() const { return dt_; }
  long step_count() const { return steps_; }
  double cfl() const { return cfl_; }
  double max_wave_speed() const { return c_max_; }

  const Discretisation<Dim>& particles() const { return disc_; }
  const CaseSetup<Dim>& setup() const { return setup_; }
  const std::vector<std::unique_ptr<Material>>& materials() const { return materials_; }
  /// Packed state (v, sigma) per node / element, NV doubles each.
  const std::vector<double>& node_phi() const { return node_phi_; }
  const std::vector<double>& element_phi() const { return elem_phi_; }
  const std::vector<double>& node_displacement() const { return node_u_; }
  const std::vector<double>& node_history() const { return node_state_; }
  const std::vector<double>& element_history() const { return elem_state_; }
  int history_stride() const { return state_stride_; }
  /// Union of the history-variable names of all materials, and where each lives per material.
  const std::vector<std::string>& history_names() const { return history_names_; }
  /// Slot of history variable `name_index` for material m, or -1 if that material lacks it.
  int history_slot(int material, std::size_t name_index) const {
    return history_slot_[static_cast<std::size_t>(material)][name_index];
  }

  /// Energies at the current time (strain energy is summed here, so call it sparingly).
  EnergyBalance energy() const;

  /// Memory held by the state and by the precomputed operators, bytes.
  std::size_t state_bytes() const;
  std::size_t operator_bytes() const;
  std::size_t pairs() const { return op_en_.pairs() + op_ne_.pairs(); }
  /// Shared row patterns of the two cross-set operators (operators/corrected_operator.hpp).
  Index operator_patterns() const { return op_en_.patterns() + op_ne_.patterns(); }
  /// Bytes one V1 step must move at least (each array a pass streams, counted once per pass):
  /// the benchmark divides it by the step time for the effective memory bandwidth.
  std::size_t step_traffic_bytes() const;
  Index degenerate_operator_rows() const { return op_en_.degenerate_rows + op_ne_.degenerate_rows; }
  long max_source_substeps() const { return max_substeps_; }
  /// Damping coefficient in force at time t: c_d before damping.until and before the
  /// kinetic-energy switch (damping.until_kinetic_ratio) has fired, else 0.
  double damping_at(double t) const {
    return (t < setup_.damping_until && t < damping_off_time_) ? setup_.damping : 0.0;
  }
  /// Time at which the kinetic-energy switch turned the damping off (infinity if it has not).
  double damping_off_time() const { return damping_off_time_; }
  double peak_kinetic_energy() const { return kinetic_peak_; }

  /// Replace the nodal velocities (tests: seed a mode and watch it).
  std::vector<double>& mutable_node_phi() { return node_phi_; }

  // ---- V3, saturated soil (METHOD.md §1.4, §2.4, §5.3; solvers/staggered_saturated.cpp).
  // node_phi holds the EFFECTIVE stress sigma'; the total stress is sigma' - p_w 1.
  bool saturated() const { return saturated_; }
  /// Pore pressure per node, Pa, compression positive (empty in V1).
  const std::vector<double>& node_pore_pressure() const { return pw_; }
  std::vector<double>& mutable_node_pore_pressure() { return pw_; }
  /// Statistics of the pressure solves (nullptr in V1) and the wall time of the whole pressure
  /// step (divergence, solve, velocity correction), s.
  const PressureSolveStats* pressure_stats() const { return pressure_ ? &pressure_->stats() : nullptr; }
  double pressure_step_seconds() const { return pressure_seconds_; }
  const PorePressureSolver* pressure_solver() const { return pressure_.get(); }
  /// V3: C c_u / c_d, the Courant number of the undrained P wave (c_u^2 = (lambda + 2G + Q)/rho),
  /// largest over the materials, and the number of boundary nodes that are neither drained nor
  /// held in their normal direction (impermeable faces carrying a prescribed, possibly zero,
  /// total stress). The step is unstable at such faces once that Courant number exceeds
  /// kUndrainedCourantLimit (docs/VALIDATION.md, Case 16).
  double undrained_courant() const { return undrained_courant_; }
  Index impermeable_stress_face_nodes() const { return impermeable_stress_faces_; }
  static constexpr double kUndrainedCourantLimit = 3.5;

 private:
  void build_constraints();
  void set_initial_state();
  void step_elements(double t);
  void step_nodes(double t);
  void filter_velocity();
  void apply_constraints(double t);
  void finish_step();
  double boundary_power() const;
  void integrate_sources(double tau, bool on_elements);
  // V3 hooks (solvers/staggered_saturated.cpp)
  void build_saturated();
  void pressure_step(double t_new);
  /// Value of a prescribed component at time t. V3: a prescribed normal stress is a TOTAL
  /// stress, so the effective stress held in phi is sigma' = sigma + p_w there.
  double constraint_value(std::size_t node, const NodalConstraint& c, double t) const {
    double v = c.value * setup_.function_value(c.function, t);
    if (saturated_ && c.component >= Dim && c.component < 2 * Dim) v += pw_[node];
    return v;
  }

  CaseSetup<Dim>& setup_;
  std::vector<std::unique_ptr<Material>> materials_;
  Discretisation<Dim> disc_;
  CubicSplineKernel<Dim> kernel_;
  CorrectedOperator<Dim> op_en_;  // nodes -> elements (step 1)
  CorrectedOperator<Dim> op_ne_;  // elements -> nodes (step 2, filter)
  DifferenceGradient<Dim> diff_ne_;  // elements -> constrained nodes, with fhat (§0.3 fix a)

  // per-material constants, indexed by material
  std::vector<double> lambda_, shear_;
  bool any_source_ = false;

  // boundary constraints, CSR per node
  std::vector<Index> constraint_row_;
  std::vector<NodalConstraint> constraints_;
  std::vector<Index> diff_row_of_node_;  // row in diff_ne_, or -1
  std::vector<Index> constrained_nodes_;  // nodes with at least one constraint, ascending
  std::vector<Index> boundary_nodes_;    // nodes on a face of the body (for traction power)

  // state
  std::vector<double> node_phi_, elem_phi_, node_u_;
  std::vector<double> node_state_, elem_state_;
  int state_stride_ = 0;
  std::vector<std::string> history_names_;
  std::vector<std::vector<int>> history_slot_;
  // runs of consecutive particles of one material with a source: (material, begin, end)
  std::vector<std::array<Index, 3>> node_runs_, elem_runs_;

  // scratch, sized once
  std::vector<double> v_half_, filter_elem_, filter_node_;  // v_half_: material velocity at t^{n+1/2}, nodes
  std::vector<double> src_sigma_start_, src_rate_, src_state_start_;
  std::vector<double> block_sums_;

  double time_ = 0.0, dt_ = 0.0, cfl_ = 0.0, c_max_ = 0.0;
  long steps_ = 0;
  long max_substeps_ = 0;
  // energy accounting
  double external_work_ = 0.0, damping_loss_ = 0.0, initial_strain_ = 0.0;
  double last_power_ = 0.0, last_damping_power_ = 0.0;
  double undrained_courant_ = 0.0;
  Index impermeable_stress_faces_ = 0;
  double initial_energy_ = 0.0;  // kinetic + strain (+ fluid storage) at the first step
  static constexpr double kEnergyGrowthLimit = 100.0;  // see finish_step
  double kinetic_peak_ = 0.0, damping_off_time_ = std::numeric_limits<double>::infinity();
  double kinetic_below_since_ = -1.0;  // time since when the kinetic energy is below the ratio, -1 = not

  // ---- V3 state (empty in V1)
  bool saturated_ = false;
  std::vector<double> pw_, pw_old_, pw_source_;
  std::vector<double> elem_v_skeleton_;  // pressure-free half-step velocity per stress point (option)
  double stabilisation_time_ = 0.0;      // dt (METHOD.md §2.4) or dt/2 (stress-point divergence)
  std::vector<double> pw_grad_;       // incremental projection: grad p^n / rho per node (Dim each)
  std::vector<bool> pw_drained_;
  std::vector<double> pw_value_;      // prescribed pore pressure at drained nodes, Pa
  std::vector<int> pw_function_;      // its time function
  CorrectedOperator<Dim> op_nn_;      // nodes -> nodes: div v*, grad p^{n+1}
  std::unique_ptr<PorePressureSolver> pressure_;
  double inv_storage_ = 0.0;          // 1/Q*, 1/Pa
  double pressure_seconds_ = 0.0;
};

}  // namespace rktsph
