#pragma once
// A case made in code (tests, benchmarks, parameter studies): the same CaseSetup the case-file
// reader makes, without writing TOML. The builder checks what the reader checks about the
// pieces it assembles (materials named by the blocks, functions named by the loads, the
// Courant limit); keys it does not set keep the reader's defaults (docs/case-format.md).
//
//   CaseSetup<2> c = CaseBuilder<2>("block")
//                        .spacing(0.1)
//                        .block({0.0, 0.0}, {10.0, 10.0})
//                        .elastic(2.0e7, 0.3, 2000.0)
//                        .fix_velocity(Region<2>::plane(1, 0.0), {0, 1})
//                        .prescribe_stress(Region<2>::plane(1, 10.0), StressComponent::yy, -1.0e4, "load")
//                        .function("load", TimeFunction::smoothstep(0.01))
//                        .time(1.0, 0.9)
//                        .build();
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "case/case_setup.hpp"
#include "core/error.hpp"
#include "materials/material.hpp"
#include "materials/uniaxial_stress.hpp"
#include "schemes/registry.hpp"
#include "schemes/time_step.hpp"

namespace rktsph {

template <int Dim>
class CaseBuilder {
 public:
  explicit CaseBuilder(std::string name = "case built in code") {
    c_.file = "<" + name + ">";
    c_.title = std::move(name);
  }

  CaseBuilder& spacing(double dx) {
    c_.dx = dx;
    return *this;
  }
  CaseBuilder& origin(const Vec<Dim>& x) {
    c_.origin = x;
    return *this;
  }
  CaseBuilder& smoothing(double h_over_dx) {
    c_.h_over_dx = h_over_dx;
    return *this;
  }
  /// A block of cells [min, max] of the named material (the only one if empty).
  CaseBuilder& block(const Vec<Dim>& min, const Vec<Dim>& max, const std::string& material = "") {
    blocks_.push_back({min, max, material});
    return *this;
  }
  /// geometry.jitter: interior particles displaced by up to `fraction` spacings (LatticeJitter).
  CaseBuilder& jitter(double fraction, std::uint64_t seed = 0) {
    c_.jitter = {fraction, seed};
    return *this;
  }
  CaseBuilder& material(std::shared_ptr<const Material> model, const std::string& name = "material") {
    c_.material_names.push_back(name);
    c_.materials.push_back(std::move(model));
    return *this;
  }
  CaseBuilder& elastic(double E, double nu, double density, const std::string& name = "material") {
    return material(std::make_shared<ElasticMaterial>(ElasticConstants::from_E_nu(E, nu, density)), name);
  }
  /// 1D: a bar in uniaxial stress instead of uniaxial strain.
  CaseBuilder& uniaxial_stress() {
    c_.condition = BarCondition::uniaxial_stress;
    return *this;
  }
  CaseBuilder& function(const std::string& name, TimeFunction f) {
    c_.function_names.push_back(name);
    c_.functions.push_back(std::move(f));
    return *this;
  }
  CaseBuilder& gravity(const Vec<Dim>& g, const std::string& function = "") {
    c_.gravity = g;
    gravity_function_ = function;
    return *this;
  }
  CaseBuilder& damping(double coefficient, double until = std::numeric_limits<double>::infinity()) {
    c_.damping = coefficient;
    c_.damping_until = until;
    return *this;
  }
  /// Prescribed velocity components (axis, m/s) on the nodes of a region.
  CaseBuilder& prescribe_velocity(const Region<Dim>& region, std::vector<std::pair<int, double>> components,
                                  const std::string& function = "") {
    BoundarySpec<Dim>& b = boundary(region, function);
    b.velocity = std::move(components);
    return *this;
  }
  /// Velocity components held at zero.
  CaseBuilder& fix_velocity(const Region<Dim>& region, const std::vector<int>& axes) {
    std::vector<std::pair<int, double>> c;
    for (int a : axes) c.emplace_back(a, 0.0);
    return prescribe_velocity(region, std::move(c));
  }
  /// A prescribed (total) stress component on the nodes of a region, Pa.
  CaseBuilder& prescribe_stress(const Region<Dim>& region, StressComponent component, double value,
                                const std::string& function = "") {
    BoundarySpec<Dim>& b = boundary(region, function);
    b.stress.emplace_back(stress_slot<Dim>(component), value);
    return *this;
  }
  /// V3: a drained face (p_w prescribed, Pa).
  CaseBuilder& drained(const Region<Dim>& region, double pore_pressure = 0.0, const std::string& function = "") {
    boundary(region, function).pore_pressure = pore_pressure;
    return *this;
  }
  /// 2D: an initial rigid motion v = velocity + omega e_z x (x - centre).
  CaseBuilder& initial_velocity(const Vec<Dim>& velocity, double omega = 0.0,
                                const Vec<Dim>& centre = Vec<Dim>::Zero()) {
    rigid_motion(velocity, centre).angular_velocity = omega;
    return *this;
  }
  /// 3D: an initial rigid motion v = velocity + omega x (x - centre).
  CaseBuilder& initial_velocity(const Vec<Dim>& velocity, const Vec<3>& omega,
                                const Vec<Dim>& centre) requires(Dim == 3) {
    rigid_motion(velocity, centre).angular_velocity_vector = omega;
    return *this;
  }
  CaseBuilder& initial_stress(const Sym6& uniform) {
    c_.initial_stress = InitialStressKind::uniform;
    c_.uniform_stress = uniform;
    return *this;
  }
  CaseBuilder& geostatic(std::optional<double> k0 = std::nullopt) {
    c_.initial_stress = InitialStressKind::geostatic;
    c_.k0 = k0;
    return *this;
  }
  /// End time and Courant number.
  CaseBuilder& time(double end, double cfl = 0.5) {
    c_.end_time = end;
    c_.cfl = cfl;
    c_.dt.reset();
    return *this;
  }
  /// time.dt_rule = "current" (V2): the step from the current state every step, at the
  /// Courant number of time() (method-notes eq. (4.3.3)).
  CaseBuilder& step_from_current_state() {
    c_.dt_from_current_state = true;
    return *this;
  }
  /// End time and a fixed step.
  CaseBuilder& time_step(double end, double dt) {
    c_.end_time = end;
    c_.dt = dt;
    c_.cfl.reset();
    return *this;
  }
  /// The scheme by registry name ("v1", "v3", ...); V2 in 2D and 3D detects its free surface
  /// by default, and V2 has the gradient floor (method-notes eq. (3.2.6)), as the reader does.
  CaseBuilder& scheme(const std::string& version) {
    c_.version = version;
    c_.detect_free_surface = version == "v2" && Dim >= 2;
    c_.gradient_floor = default_gradient_floor<Dim>(version);
    return *this;
  }
  /// solver.gradient_floor (method-notes eq. (3.2.6); 0: off).
  CaseBuilder& gradient_floor(double floor) {
    c_.gradient_floor = floor;
    return *this;
  }
  /// solver.free_surface: detected ("detect", V2 in 2D/3D) or the lattice faces ("faces").
  CaseBuilder& free_surface(bool detect) {
    c_.detect_free_surface = detect;
    return *this;
  }
  /// solver.reseed (V2): when to re-seed the stress points, at most every `interval` steps
  /// (by default the reader's: 5 for "auto", 20 for "periodic").
  CaseBuilder& reseed(ReseedSetting when, long interval = 0) {
    c_.reseed = when;
    c_.reseed_interval = interval > 0 ? interval : (when == ReseedSetting::periodic ? 20 : 5);
    return *this;
  }
  /// solver.shift (V2): when to shift the nodes, at most every `interval` steps.
  CaseBuilder& shift(ShiftSetting when, long interval = 20) {
    c_.shift = when;
    c_.shift_interval = interval;
    return *this;
  }
  /// solver.domain_min / domain_max (V2): particles leaving the box are deactivated.
  CaseBuilder& domain_box(const Vec<Dim>& lo, const Vec<Dim>& hi) {
    c_.domain_box = std::array<Vec<Dim>, 2>{lo, hi};
    return *this;
  }
  CaseBuilder& fluid(const FluidSpec& f) {
    c_.fluid = f;
    return *this;
  }
  CaseBuilder& velocity_filter(bool on, double strength = 0.5) {
    c_.filter = on;
    c_.filter_strength = strength;
    return *this;
  }

  /// The case, checked. Throws InputError naming what is missing or inconsistent.
  CaseSetup<Dim> build() const {
    CaseSetup<Dim> c = c_;
    auto fail = [&](const std::string& what) { throw InputError(fmt::format("{}: {}", c.file, what)); };
    if (c.detect_free_surface && (c.version != "v2" || Dim < 2))
      fail("free-surface detection needs the V2 scheme in 2D or 3D");
    if (c.domain_box && c.version != "v2") fail("a domain box needs the V2 scheme");
    if (c.dt_from_current_state && (c.version != "v2" || c.dt))
      fail("a step from the current state needs the V2 scheme and a Courant number, not a fixed step");
    if (!(c.dx > 0.0)) fail("the spacing must be > 0");
    if (!(c.jitter.fraction >= 0.0 && c.jitter.fraction < kMaxJitterFraction))
      fail(fmt::format("the jitter must lie in [0, {}) spacings", kMaxJitterFraction));
    if (c.materials.empty()) fail("no material");
    if (blocks_.empty()) fail("no block");
    if (!(c.end_time > 0.0)) fail("the end time must be > 0");
    for (std::size_t k = 0; k < blocks_.size(); ++k) {
      Block<Dim> b{blocks_[k].min, blocks_[k].max, 0, fmt::format("block {}", k)};
      b.material = material_index(blocks_[k].material, fail);
      c.blocks.push_back(b);
    }
    c.gravity_function = function_index(c, gravity_function_, fail);
    for (std::size_t k = 0; k < c.boundaries.size(); ++k) {
      c.boundaries[k].function = function_index(c, boundary_functions_[k], fail);
    }
    if (Dim == 1 && c.condition == BarCondition::uniaxial_stress) {
      for (auto& m : c.materials) m = std::make_shared<UniaxialStressMaterial>(m);
    }
    const SchemeInfo* scheme = find_scheme<Dim>(c.version);
    if (scheme == nullptr) fail(fmt::format("no scheme '{}' in {}D", c.version, Dim));
    if (scheme->pore_fluid && !(c.fluid.bulk_modulus > 0.0 && c.fluid.porosity > 0.0)) {
      fail(fmt::format("the scheme '{}' needs a pore fluid (porosity and bulk modulus > 0)", c.version));
    }
    const TimeStep step = time_step_from(c.dx, max_wave_speed(c.materials), c.cfl, c.dt);
    if (step.courant > kMaxCourant) {
      fail(fmt::format("the Courant number {:.3f} exceeds {} (method-notes §0.3 item 4)", step.courant, kMaxCourant));
    }
    return c;
  }

 private:
  // The one initial-velocity entry of a rigid motion, its rotation left to the caller.
  InitialVelocitySpec<Dim>& rigid_motion(const Vec<Dim>& velocity, const Vec<Dim>& centre) {
    InitialVelocitySpec<Dim> spec;
    spec.where = "CaseBuilder::initial_velocity";
    spec.velocity = velocity;
    spec.centre = centre;
    c_.initial_velocities = {spec};
    return c_.initial_velocities.front();
  }
  struct PendingBlock {
    Vec<Dim> min, max;
    std::string material;
  };

  BoundarySpec<Dim>& boundary(const Region<Dim>& region, const std::string& function) {
    BoundarySpec<Dim> b;
    b.name = fmt::format("boundary {}", c_.boundaries.size());
    b.where = c_.file + ", " + b.name;
    b.region = region;
    c_.boundaries.push_back(b);
    boundary_functions_.push_back(function);
    return c_.boundaries.back();
  }

  template <class Fail>
  int material_index(const std::string& name, Fail&& fail) const {
    if (name.empty()) {
      if (c_.materials.size() != 1) fail("several materials: name each block's material");
      return 0;
    }
    for (std::size_t i = 0; i < c_.material_names.size(); ++i) {
      if (c_.material_names[i] == name) return static_cast<int>(i);
    }
    fail(fmt::format("no material named '{}'", name));
    return -1;
  }
  template <class Fail>
  static int function_index(const CaseSetup<Dim>& c, const std::string& name, Fail&& fail) {
    if (name.empty()) return -1;
    for (std::size_t i = 0; i < c.function_names.size(); ++i) {
      if (c.function_names[i] == name) return static_cast<int>(i);
    }
    fail(fmt::format("no time function named '{}'", name));
    return -1;
  }

  CaseSetup<Dim> c_;
  std::vector<PendingBlock> blocks_;
  std::string gravity_function_;
  std::vector<std::string> boundary_functions_;
};

}  // namespace rktsph
