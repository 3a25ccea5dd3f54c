#pragma once
// The shared room of the staggered schemes (V1 dry, V3 saturated; method-notes §3.3, §5.1,
// §5.3): the two particle sets and their fields, the materials, the corrected operators
// between the sets, the boundary constraints and the loads. Stages (schemes/stage.hpp) act on
// it; a scheme is a list of them (schemes/scheme.hpp).
//
// Nodes carry the state at t^n (velocity, stress, displacement, history); stress points carry
// the half-step state at t^{n+1/2} (velocity, stress, history). The particles do not move in
// these schemes, so the operators are built once, from relations that are then released.
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "bc/constraints.hpp"
#include "bodies/plates.hpp"
#include "case/case_setup.hpp"
#include "core/execution.hpp"
#include "core/kernel.hpp"
#include "materials/history_layout.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/lattice.hpp"
#include "particles/particle_set.hpp"
#include "schemes/time_step.hpp"

namespace rktsph {

/// Handles of the fields the staggered schemes register.
template <int Dim>
struct StaggeredFields {
  static constexpr int NS = kStressComponents<Dim>;
  // nodes, t^n
  Field<double, Dim> velocity;      // m/s
  Field<double, NS> stress;         // Pa (effective stress sigma' in V3)
  Field<double, Dim> displacement;  // m
  Field<double, 0> history;         // the materials' history variables (HistoryLayout)
  Field<double, 1> pore_pressure;   // Pa, compression positive; valid only in saturated schemes
  // stress points, t^{n+1/2}
  Field<double, Dim> sp_velocity;
  Field<double, NS> sp_stress;
  Field<double, 0> sp_history;
};

/// The materials as the stages use them: the models, and per material the constants hoisted
/// out of the loops.
struct MaterialTable {
  std::vector<std::shared_ptr<const Material>> models;
  std::vector<ElasticRate> elastic;  // per material
  std::vector<double> p_modulus;     // per material: rho c^2 of its fastest wave, Pa
  std::vector<double> density;       // per material: its reference density, kg/m^3
  HistoryLayout history;
  bool any_source = false;
  const Material& operator[](int m) const { return *models[static_cast<std::size_t>(m)]; }
};

/// Runs of consecutive particles of one material that has a source: (material, begin, end),
/// cut into chunks for the threads.
using SourceRuns = std::vector<std::array<Index, 3>>;

template <int Dim>
class StaggeredModel {
 public:
  static constexpr int NS = kStressComponents<Dim>;

  /// Particles, materials, time step, operators and constraints of a case. Throws InputError
  /// for a case the schemes cannot run (a Courant number above kMaxCourant).
  explicit StaggeredModel(CaseSetup<Dim> setup, exec::Threads policy = {});

  CaseSetup<Dim> setup;
  exec::Threads policy;
  CubicSplineKernel<Dim> kernel;
  MaterialTable materials;
  Lattice<Dim> lattice;
  ParticleSet<Dim> nodes{"nodes"};
  ParticleSet<Dim> stress_points{"stress_points"};
  BoundaryNodes<Dim> boundary;
  StaggeredFields<Dim> fields;
  TimeStep time_step;

  CorrectedOperator<Dim> to_stress_points;  // nodes -> stress points (step 1)
  CorrectedOperator<Dim> to_nodes;          // stress points -> nodes (step 2, filter)
  NodalConstraints<Dim> constraints;
  /// Stress points -> constrained nodes, in the difference form (method-notes §0.3 item 1 fix (a)).
  DifferenceGradient<Dim> constrained_gradient;
  /// V2's detected free surface (schemes/v2_stages.hpp), empty otherwise: each node's row or -1,
  /// and per row the outward normal and the difference gradient from the stress points, with
  /// which step 2 sees the traction-free condition (method-notes §3.7, fix (a) of §0.3 item 1).
  struct SurfaceRows {
    std::vector<Index> row;
    std::vector<Vec<Dim>> normal;
    std::vector<std::uint8_t> corner;  // 1: faces meet there with no single normal (method-notes §3.6)
    std::vector<Vec<Dim>> edge;        // 3D: the direction of the edge the row is on, else zero; may be empty
    DifferenceGradient<Dim> gradient;
    /// Polygon edges with a prescribed traction (V1, method-notes §3.9): per row (normal,
    /// tangential) in Pa and its time function; empty where every row is traction-free.
    std::vector<Vec<Dim>> traction;
    std::vector<int> traction_function;
  } surface;
  /// V2's contact nodes with rigid bodies (schemes/v2_stages.hpp, method-notes §4.5), empty
  /// otherwise: each node's row or -1, and per row the body's normal, whether the tangential
  /// velocity is held too (stick, or two bodies), the body's velocity at t^{n+1/2} and the
  /// difference gradient from the stress points, with which step 2 takes the constrained
  /// velocity components in their own gradient (fix (a) of §0.3 item 1).
  struct ContactRows {
    std::vector<Index> row;
    std::vector<Vec<Dim>> normal;
    std::vector<std::uint8_t> full;
    std::vector<Vec<Dim>> velocity;
    DifferenceGradient<Dim> gradient;
  } contact;
  SourceRuns node_sources, stress_point_sources;
  /// Rigid bodies in small deformation (V1, V3 in 2D; bodies/plates.hpp, method-notes §4.6):
  /// null without [[body]] and in V2, whose bodies move (bodies/contact.hpp).
  std::shared_ptr<RigidPlates> plates;

  double dx() const { return setup.dx; }
  double function_value(int f, double t) const { return setup.function_value(f, t); }
  /// Body force per unit mass at time t, m/s^2.
  Vec<Dim> body_force(double t) const { return function_value(setup.gravity_function, t) * setup.gravity; }

  /// Whether prescribed component c of node i is a lattice face's traction-free normal stress
  /// on the face that a rigid body presses at this step (V2, method-notes §4.5): the contact
  /// makes that stress a reaction, so it is not imposed (a node that a boundary entry selects,
  /// as on a symmetry axis under a footing, keeps its faces' defaults otherwise).
  bool released_by_contact(Index i, const NodalConstraint& c) const {
    if (!c.face_default || contact.row.empty()) return false;
    const Index r = contact.row[static_cast<std::size_t>(i)];
    if (r < 0) return false;
    const Vec<Dim>& n = contact.normal[static_cast<std::size_t>(r)];
    for (int d = 0; d < Dim; ++d) {
      if (c.component == Dim + stress_slot<Dim>(d, d) && std::abs(std::abs(n[d]) - 1.0) < 1e-9) return true;
    }
    return false;
  }
  /// Value of a prescribed component at node i at time t. A prescribed normal stress is a
  /// TOTAL stress: with a pore pressure the effective stress held is sigma + p_w.
  double constraint_value(Index i, const NodalConstraint& c, double t) const {
    if (c.body >= 0) return plates->velocity_at(static_cast<std::size_t>(c.body), c.component, t);
    double v = c.value * function_value(c.function, t);
    if (pore_pressure_ != nullptr && c.component >= Dim && c.component < 2 * Dim) v += pore_pressure_[i];
    return v;
  }
  /// Overwrite the prescribed components with their values at time t.
  void apply_constraints(double t);
  /// Add to the traction-free stress `sigma` of surface row `row` its prescribed traction at
  /// time t (polygon edges with a `traction`, method-notes §3.9).
  void add_surface_traction(std::size_t row, double t, double* sigma) const;
  /// Power of the surface tractions on the body, W (per unit thickness in 2D): the sum over
  /// face nodes of A (sigma . n) . v, with the total stress.
  double boundary_power() const;
  /// Kinetic energy of the prescribed velocity components, J (per unit thickness in 2D):
  /// sum over constrained nodes of m v_k^2 / 2 for each prescribed axis k. The boundary imposes
  /// it before any work is done (a kinematic load starting from rest); the growth guard counts it.
  double imposed_kinetic() const;

  /// The fastest P-wave over both particle sets at their current densities, m/s:
  /// max c_m (rho_m / rho_i)^(1/2) (method-notes eq. (4.3.3); particles without volume, frozen
  /// outside the domain box, do not count). The largest ratio is returned in `stretch`.
  double current_wave_speed(double* stretch = nullptr) const;

  /// Initial velocity, stress and history (method-notes §4.2), then the constraints at t = 0.
  void set_initial_state();

  /// A saturated scheme registers the node pore pressure here: constraints and the traction
  /// power then use the total stress sigma' - p_w 1.
  void set_pore_pressure(Field<double, 1> field);

  /// After the stress points were replaced (re-seeding, particles/reseed.hpp): the per-set
  /// tables made from them (the source runs); the operators are rebuilt by the V2 stage.
  void stress_points_changed();

  /// Reorder the particle sets (Reordering: new particle k is old order[k]), with every table
  /// the model keeps by particle index: the constraints, the boundary faces, the source runs,
  /// the surface rows. The stages follow through Scheme::reordered. Operators and relations
  /// are stale afterwards: the caller rebuilds them (V2 sorts just before its neighbour search).
  void reorder(const Reordering& reordering);
  /// How many reorderings changed the order so far (probes and outputs that hold indices check it).
  long reorders() const { return reorders_; }

  /// Memory of the particle state and of the operators, bytes.
  std::size_t state_bytes() const { return nodes.bytes() + stress_points.bytes(); }
  std::size_t operator_bytes() const;
  std::size_t pairs() const { return to_stress_points.pairs() + to_nodes.pairs(); }
  Index degenerate_operator_rows() const { return to_stress_points.degenerate_rows + to_nodes.degenerate_rows; }
  /// Rows of the two operators regularised by the gradient floor (method-notes eq. (3.2.6)).
  Index regularised_operator_rows() const { return to_stress_points.regularised_rows + to_nodes.regularised_rows; }

 private:
  const double* pore_pressure_ = nullptr;
  long reorders_ = 0;
};

}  // namespace rktsph
