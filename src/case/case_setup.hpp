#pragma once
// A case as the schemes see it: plain data, made by the case-file reader (case/case_reader.hpp,
// which alone knows TOML) or in code (case/case_builder.hpp). Every key is documented in
// docs/case-format.md.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bc/time_function.hpp"
#include "bodies/rigid_body.hpp"
#include "core/types.hpp"
#include "materials/material.hpp"
#include "particles/lattice.hpp"
#include "particles/polygon.hpp"

namespace rktsph {

/// Default of time.max_steps: a run of more steps must say so in its case file.
inline constexpr double kDefaultMaxSteps = 1.0e8;

/// Default of solver.gradient_floor (method-notes eq. (3.2.6)) for a solver version: on for V2,
/// at 0.05 in 1D and 2D and 0.025 in 3D, under every row of a lattice at h = 1.2 dx (the corner
/// node's row from the stress points: 0.126 / 0.058 / 0.028); off (0) for V1 and V3, whose
/// particles do not move.
template <int Dim>
double default_gradient_floor(const std::string& version) {
  if (version != "v2") return 0.0;
  return Dim == 3 ? 0.025 : 0.05;
}

/// Nodes selected by an axis-aligned box; an axis left open selects everything along it.
template <int Dim>
struct Region {
  std::array<double, Dim> lo{};
  std::array<double, Dim> hi{};
  std::array<bool, Dim> bounded{};
  /// The plane x_axis = coord (every node on it).
  static Region plane(int axis, double coord) {
    Region r;
    r.lo[static_cast<std::size_t>(axis)] = r.hi[static_cast<std::size_t>(axis)] = coord;
    r.bounded[static_cast<std::size_t>(axis)] = true;
    return r;
  }
  /// The box [lo, hi] (every axis bounded).
  static Region box(const Vec<Dim>& lo, const Vec<Dim>& hi) {
    Region r;
    for (std::size_t d = 0; d < Dim; ++d) {
      r.lo[d] = lo[static_cast<int>(d)];
      r.hi[d] = hi[static_cast<int>(d)];
      r.bounded[d] = true;
    }
    return r;
  }
  bool contains(const Vec<Dim>& x, double tol) const {
    for (std::size_t d = 0; d < Dim; ++d) {
      if (bounded[d] && (x[static_cast<int>(d)] < lo[d] - tol || x[static_cast<int>(d)] > hi[d] + tol)) return false;
    }
    return true;
  }
};

/// An initial velocity entry (docs/case-format.md "[initial_velocity]"): a uniform velocity, a
/// rigid rotation and a function of position, on the nodes it selects by material and box; a
/// later entry replaces an earlier one on the nodes both select.
template <int Dim>
struct InitialVelocitySpec {
  std::string where;                     // "case.toml, line 12, key 'initial_velocity'" for error messages
  Region<Dim> region;                    // no axis bounded: every node
  int material = -1;                     // index into CaseSetup::materials, -1: any
  Vec<Dim> velocity = Vec<Dim>::Zero();  // m/s
  /// 2D: v += omega e_z x (x - centre) (rad/s, counter-clockwise positive).
  double angular_velocity = 0.0;
  /// 3D: v += omega x (x - centre), omega the angular velocity vector (rad/s, right-handed).
  Vec<3> angular_velocity_vector = Vec<3>::Zero();
  Vec<Dim> centre = Vec<Dim>::Zero();
  /// A function of the initial position per component (muparser syntax in x, y, z; m/s), added to
  /// the rest; empty: none.
  std::array<std::string, Dim> expression{};
};

template <int Dim>
struct BoundarySpec {
  std::string name;
  std::string where;  // "case.toml, line 12" for error messages
  Region<Dim> region;
  /// An edge of a polygon body (particles/polygon.hpp) instead of a region: the entry selects
  /// the nodes on it; `region` is then the edge's bounding box (for the partial-load average).
  std::optional<EdgeRef> edge;
  std::vector<std::pair<int, double>> velocity;  // (axis, m/s)
  std::vector<std::pair<int, double>> stress;    // (stress slot, Pa)
  /// On a polygon edge normal to no axis: the traction (normal, tangential) in Pa, tension
  /// positive, t = e_z x n (method-notes §3.9), imposed by the rotation of §3.7.
  std::optional<std::array<double, 2>> traction;
  int function = -1;  // index into CaseSetup::functions, -1 = 1
  /// V1/V3: the velocity components are those of rigid body `body` (bodies/plates.hpp), not
  /// value * function; -1 = none. Made by the model from a [[body]], not read from [[boundary]].
  int body = -1;
  // V3 (saturated) pore-pressure conditions, method-notes §4.1: a drained face (p_w prescribed,
  // Pa, scaled by `function`) or an explicitly impermeable one (dp_w/dn = 0, the default).
  std::optional<double> pore_pressure;
  bool impermeable = false;
};

/// V3: the pore fluid and the pressure solver (case keys [fluid], docs/case-format.md
/// "Saturated soil (V3)"). The material `density` is the MIXTURE density
/// rho = n rho_f + (1 - n) rho_s.
struct FluidSpec {
  double porosity = 0.0;            // n
  double density = 1000.0;          // rho_f, kg/m^3
  double bulk_modulus = 0.0;        // K_f, Pa
  double grain_bulk_modulus = 0.0;  // K_s, Pa; 0 = incompressible grains
  double conductivity = 0.0;        // k, m/s
  double gravity = 9.81;            // g used in k_w = k / (rho_f g), m/s^2
  double saturation = 1.0;          // S_w
  double tolerance = 1e-8;          // relative residual of the PCG
  int max_iterations = 2000;
  bool incomplete_cholesky = false;  // preconditioner: false = Jacobi (default)
  bool deferred_correction = true;   // Schwaiger correction on the right-hand side
  /// Incremental pressure projection (method-notes §2.4 "Incremental variant"): the stabilisation
  /// (S_w dt/rho) L acts on p^{n+1} - p^n instead of p^{n+1}.
  bool incremental = true;
  /// solver.pressure_divergence: which volumetric rate drives the storage equation (method-notes
  /// §2.4). consistent (default): the stress points' divergence, the rate that sigma' integrates,
  /// plus the change of the nodes' divergence over the step (eq. (2.4.20)); nodes: div v* at the
  /// nodes (eq. (2.4.8)); stress_points: div of the stress points' pressure-free half-step
  /// velocity with the stabilisation S_w (dt/2)/rho (eq. (2.4.14)).
  enum class StorageRate { consistent, nodes, stress_points };
  StorageRate storage_rate = StorageRate::consistent;
  /// solver.pressure_faces: the effective-stress condition at impermeable faces that carry a
  /// total stress, taken at t^{n+1} in the pressure step (implicit, method-notes eq. (2.4.16)) or
  /// with p^n (explicit: stable only below C c_u/c_d = 3.5, eq. (4.3.2)); automatic: implicit
  /// where the explicit form is within reach of its limit (C c_u/c_d > 2.5), else explicit.
  enum class FaceCondition { automatic, implicit, explicit_p };
  FaceCondition face_condition = FaceCondition::automatic;
  /// solver.pressure_filter: coefficient of the linear-exact pressure filter, in units of the
  /// fractional-step stabilisation S_w dt/rho (0 = none, the default; method-notes §2.4).
  double filter = 0.0;
  /// solver.pressure_filter_gradient: the gradient in the filter's psi_IJ (method-notes eq.
  /// (2.4.18)). quadratic_drained (default): exact for quadratic fields on the rows whose support
  /// holds a drained node, so that the filter does not drain the curved pressure there; quadratic:
  /// on every row; linear: the velocity correction's linear-exact gradient everywhere.
  enum class FilterGradient { quadratic_drained, quadratic, linear };
  FilterGradient filter_gradient = FilterGradient::quadratic_drained;
  /// solver.pressure_odd_even_filter: the fraction alpha of the local odd-even amplitude taken
  /// off p_w after each solve, p <- p - alpha a (method-notes eq. (2.4.19)); 0 = off.
  double odd_even_filter = 1.0;
  double initial_pore_pressure = 0.0;  // Pa, uniform
  /// 1/Q* = S_w n / K_f + (1 - n)/K_s (method-notes §1.4), 1/Pa
  double inverse_storage() const {
    return saturation * porosity / bulk_modulus +
           (grain_bulk_modulus > 0.0 ? (1.0 - porosity) / grain_bulk_modulus : 0.0);
  }
  /// k_w = k / (rho_f g), m^3 s / kg
  double permeability() const { return conductivity / (density * gravity); }
};

struct ProbeSpec {
  std::string name;
  std::string where;         // the position's place in the case file, for its messages
  std::string fields_where;  // the fields' place, for an unknown field
  std::vector<double> position;
  std::vector<std::string> fields;
};

/// When V2 re-seeds its stress points (solver.reseed).
enum class ReseedSetting { off, automatic, periodic };
/// When V2 sorts its particles into Morton order (solver.sort).
enum class SortSetting { off, automatic, always };

/// When V2 shifts its nodes (solver.shift).
enum class ShiftSetting { off, automatic, periodic };
/// What V2's nodal stress filter acts on (solver.stress_filter_part, method-notes eq. (2.3.4)).
enum class StressFilterPart { mean, full };

enum class InitialStressKind { zero, geostatic, uniform };
/// 1D only: the lateral condition of the bar (docs/cases.md §1.1, Case 2).
enum class BarCondition { uniaxial_strain, uniaxial_stress };
/// solver.scheme: two interleaved sets (the method), or one set holding both states (a comparison).
enum class ParticleLayout { staggered, collocated };

template <int Dim>
struct CaseSetup {
  std::string file;
  std::string title;

  // materials (a 1D bar in uniaxial stress has them wrapped in UniaxialStressMaterial)
  std::vector<std::string> material_names;
  std::vector<std::shared_ptr<const Material>> materials;

  // geometry
  double dx = 0.0;
  Vec<Dim> origin = Vec<Dim>::Zero();
  std::vector<Block<Dim>> blocks;
  /// geometry.polygon (2D): polygon bodies (particles/polygon.hpp). The reader discretises them
  /// into `imported` (with their faces); the geometry is kept for the edges' boundary entries
  /// and for the commands that read it (rktsph lem).
  std::vector<PolygonBody> polygons;
  /// geometry.jitter and geometry.jitter_seed (particles/lattice.hpp, LatticeJitter).
  LatticeJitter jitter;
  /// geometry.particles: nodes and stress points read from files (case/particle_file_reader.hpp)
  /// instead of generated from blocks. Without the face columns the nodes lie on no face
  /// (`boundary` stays empty) and the free surface must be detected (solver.free_surface =
  /// "detect", V2 in 2D); with them, `boundary` holds the faces as a lattice would.
  struct ImportedParticles {
    ParticleSet<Dim> nodes{"nodes"};
    ParticleSet<Dim> stress_points{"stress_points"};
    BoundaryNodes<Dim> boundary;
    bool faces_given = false;
  };
  std::optional<ImportedParticles> imported;
  /// 1D: uniaxial strain (lateral strains zero; modulus lambda + 2G) or uniaxial stress
  /// (lateral stresses zero; modulus E, materials wrapped by UniaxialStressMaterial).
  BarCondition condition = BarCondition::uniaxial_strain;

  // kernel
  double h_over_dx = 1.2;
  /// The kernel's smoothing length h = h_over_dx * dx, m (method-notes §3.1).
  double smoothing_length() const { return h_over_dx * dx; }

  // loads
  Vec<Dim> gravity = Vec<Dim>::Zero();  // m/s^2
  int gravity_function = -1;
  double damping = 0.0;        // 1/s, velocity damping source -c_d v (method-notes §4.2)
  double damping_until = 0.0;  // s: damping switched off from this time on
  /// s: damping also switched off once the kinetic energy has fallen below this fraction of
  /// its peak (0 = never), tested from damping_ratio_from on (e.g. the end of a gravity ramp)
  double damping_until_kinetic_ratio = 0.0;
  double damping_ratio_from = 0.0;
  double damping_ratio_hold = 0.0;  // s the kinetic energy must stay below the ratio before the switch
  std::vector<BoundarySpec<Dim>> boundaries;
  /// [[body]]: rigid bodies in contact with the nodes (V2 in 2D; bodies/contact.hpp).
  std::vector<BodySpec> bodies;

  // initial state
  InitialStressKind initial_stress = InitialStressKind::zero;
  std::optional<double> k0;             // geostatic lateral coefficient; default nu/(1-nu)
  std::optional<double> surface_level;  // geostatic ground surface (vertical axis = last axis)
  Sym6 uniform_stress{};                // uniform initial stress (xx, yy, zz, xy, yz, xz), Pa
  /// Initial velocity entries, so that impacts and spinning bodies need no boundary entry per
  /// node; none: at rest.
  std::vector<InitialVelocitySpec<Dim>> initial_velocities;

  // time
  double end_time = 0.0;
  std::optional<double> cfl;
  std::optional<double> dt;
  /// time.dt_rule = "current" (V2): the step recomputed every step from the current density,
  /// dt^n = C dx / max_i c_i(rho_i^n) (method-notes eq. (4.3.3)); false: fixed (time.dt or
  /// C dx / c on the initial state).
  bool dt_from_current_state = false;
  /// time.max_steps: the run is refused before it starts if end_time / dt exceeds it
  /// (case/size_limits.hpp).
  double max_steps = kDefaultMaxSteps;

  // solver
  /// The scheme, by its registry name (solver.version): "v1" dry, "v3" saturated (the v-p_w
  /// model, method-notes §1.4, §5.3); schemes/registry.hpp lists them.
  std::string version = "v1";
  ParticleLayout layout = ParticleLayout::staggered;  // solver.scheme
  FluidSpec fluid;
  bool filter = true;
  double filter_strength = 0.5;
  /// V2: the nodal velocity of step 2 by V1's Taylor-Galerkin step followed by the mode-selective
  /// hourglass control (method-notes §2.6; solver.velocity_update = "hourglass", the default),
  /// or by the thesis's simple scheme (method-notes §2.3; "simple"). Both false: V1's step 2 with
  /// its velocity filter alone (tests and benchmarks only).
  bool simple_velocity = false;
  bool hourglass = true;
  /// V2, simple scheme: the weight of the simple scheme's velocity in the nodal update, the
  /// rest V1's step 2 (method-notes eq. (2.3.2); solver.simple_weight). 1: the simple scheme.
  double simple_weight = 1.0;
  /// V2: the weight of the stress points' stress in the nodal stress update, the rest the nodes'
  /// own full step (method-notes eq. (2.3.3); solver.simple_stress_weight). 0: the nodes
  /// integrate their own stress; a positive weight removes the nodal stress modes the stress
  /// points do not see at (1 - weight) a step.
  double simple_stress_weight = 0.0;
  /// V2: the strength eps of the fourth-order filter on the nodal stress, sigma <- sigma - eps
  /// (I - P_NE P_EN)^2 sigma after step 2 (method-notes eq. (2.3.4); solver.stress_filter).
  /// 0: off. It removes the nodal stress mode at eps a step and leaves linear fields exactly.
  double stress_filter = 0.0;
  /// What the stress filter acts on (solver.stress_filter_part): the mean stress (default) or
  /// every component.
  StressFilterPart stress_filter_part = StressFilterPart::mean;
  /// The corrected operators' gradient floor (method-notes eq. (3.2.6); solver.gradient_floor):
  /// a row whose gradient renormalisation matrix has an eigenvalue below it (a thin sheet of
  /// particles, a lone particle) is regularised. The reader's default: default_gradient_floor.
  double gradient_floor = 0.0;
  /// The traction-free surface (method-notes §3.6-3.7, §4.1): on the faces of the initial
  /// lattice in global axes (V1, V3, and V2 in 1D), or, for V2 in 2D and 3D, detected on the
  /// current positions every step with its normals, the stress rotated to sigma.n = 0 there
  /// (solver.free_surface = "faces" | "detect").
  bool detect_free_surface = false;
  /// The detection's settled interior (method-notes §3.6): every node is evaluated again once
  /// some node has moved more than surface_refresh * dx (or changed its volume by more than 2 %)
  /// since the last full pass; 0: every step.
  double surface_refresh = 0.1;
  /// The detection's mirror images at rigid bodies (method-notes §3.6, "Mirror images at rigid
  /// bodies"; solver.surface_mirrors): a node beside a body that the soil reaches sums the
  /// reflections of its neighbours across the body's face, for the detection only.
  bool surface_mirrors = false;
  SourceCoupling coupling = SourceCoupling::additive;
  /// V2: the stress points re-seeded from the node cloud (method-notes §5.2, "Regularisation";
  /// solver.reseed): never, when the sets drift apart (eq. (5.2.4): more particles than after
  /// the last re-seeding have no particle of the other set within reseed_distance * dx), or
  /// every reseed_interval steps; at most once per reseed_interval steps. A cell gets a stress
  /// point where the nodes fill at least reseed_fill of it (eq. (5.2.1)).
  ReseedSetting reseed = ReseedSetting::off;
  long reseed_interval = 5;  // the reader's default for "periodic" is 20
  double reseed_fill = 0.5;
  double reseed_distance = 1.0;
  double reseed_cover = 0.45;  // solver.reseed_cover: less-filled cells with a node near the centre
  /// V2 in 2D/3D: the nodes pushed apart where they crowd (method-notes §5.2,
  /// "Regularisation", eqs. (5.2.5)-(5.2.7); solver.shift): never, when two nodes come closer
  /// than shift_distance * dx (checked every shift_interval steps), or every shift_interval
  /// steps; shift_strength is beta of eq. (5.2.6).
  ShiftSetting shift = ShiftSetting::off;
  long shift_interval = 20;
  double shift_strength = 0.01;
  double shift_distance = 0.5;
  /// V2: when the particle sets are sorted into Morton order of their cells (method-notes
  /// §3.8, "Storage order"; solver.sort): never, at a neighbour search once the storage order
  /// has become disordered (the mean index gap of neighbour pairs doubled), or at every search.
  SortSetting sort = SortSetting::automatic;
  /// V2: the corrected operators applied on the fly in the steps, from the current positions,
  /// without storing a weight per pair (method-notes §5.2, "Operators on the fly"), or stored
  /// as weights rebuilt at the start of every step (solver.operators = "on_the_fly" |
  /// "stored"; "auto" is on the fly: a nodal filter then applies the interpolation weights
  /// that steps 1 and 2 keep, MovingOperators::record_interpolation).
  bool operators_on_the_fly = true;
  /// V2: the domain box [min, max] (solver.domain_min / domain_max): particles that leave it
  /// are deactivated (schemes/deactivate_stage.hpp); empty: no box. `domain_where` names the
  /// keys' file and line for the errors found once the particles exist.
  std::optional<std::array<Vec<Dim>, 2>> domain_box;
  std::string domain_where;

  // output
  double output_interval = 0.0;  // s; 0 = first and last state only
  /// s of simulated time between checkpoints; empty = a tenth of the run; 0 = none but the one
  /// written when the run is interrupted (docs/output.md, "Interrupted runs").
  std::optional<double> checkpoint_interval;
  std::vector<double> output_times;  // s; extra snapshots
  bool output_elements = true;
  int probe_every = 1;
  std::vector<ProbeSpec> probes;

  /// Warnings of the reader (also written to stderr when the case is read), e.g. snapshot
  /// times past the end.
  std::vector<std::string> warnings;

  std::vector<std::string> function_names;
  std::vector<TimeFunction> functions;
  double function_value(int index, double t) const {
    return index < 0 ? 1.0 : functions[static_cast<std::size_t>(index)](t);
  }
};

}  // namespace rktsph
