// Reading and checking a TOML case file (docs/case-format.md). Every error names the file,
// the line and the key, and is an InputError (exit status 2).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "case/body_reader.hpp"
#include "case/case_reader.hpp"
#include "case/case_reader_sections.hpp"
#include "case/material_reader.hpp"
#include "case/polygon_reader.hpp"
#include "case/size_limits.hpp"
#include "core/error.hpp"
#include "io/section.hpp"
#include "materials/uniaxial_stress.hpp"
#include "schemes/registry.hpp"
#include "schemes/time_step.hpp"

namespace rktsph {

using namespace case_reading;

template <int Dim>
CaseSetup<Dim> read_case(const CaseDocument& doc) {
  CaseSetup<Dim> c;
  c.file = doc.file;
  io::Section root(doc.table, "", doc.file_label);
  c.title = root.string("title", "");
  (void)root.optional_table("fos");  // read by `rktsph fos` (app/fos_setup.cpp); a run ignores it

  // ---- time functions (read first: other tables refer to them by name)
  if (auto fs = root.optional_table("functions")) {
    for (const std::string& name : fs->keys()) {
      c.function_names.push_back(name);
      c.functions.push_back(read_time_function(fs->table(name)));
    }
    fs->finish();
  }

  // ---- materials: one [material] table or named [materials.NAME] tables
  const bool single = root.has("material");
  const bool named = root.has("materials");
  if (single && named) root.fail("materials", "give either [material] or [materials.NAME], not both");
  if (!single && !named) root.fail("material", "missing: the case needs a [material] table");
  if (single) {
    const io::Section m = root.table("material");
    c.material_names.push_back("material");
    c.materials.push_back(read_material(m));
    m.finish();
  } else {
    const io::Section ms = root.table("materials");
    for (const std::string& name : ms.keys()) {
      const io::Section m = ms.table(name);
      c.material_names.push_back(name);
      c.materials.push_back(read_material(m));
      m.finish();
    }
    ms.finish();
  }

  // ---- geometry (the section is kept: the memory estimate below names its spacing)
  const io::Section g = root.table("geometry");
  std::string particles_where;  // the first [[geometry.particles]], for the checks below
  {
    g.integer("dimension");
    c.dx = g.positive("spacing");
    if (g.has("condition")) {
      // docs/cases.md §1.1 / Case 2: a 1D bar in uniaxial strain (default) or uniaxial stress.
      const std::string cond = g.string("condition");
      if (Dim != 1) g.fail("condition", "only a 1D case takes a lateral condition (2D is plane strain)");
      if (cond == "uniaxial_strain")
        c.condition = BarCondition::uniaxial_strain;
      else if (cond == "uniaxial_stress")
        c.condition = BarCondition::uniaxial_stress;
      else
        g.fail("condition", fmt::format("unknown condition '{}' (known: uniaxial_strain, uniaxial_stress)", cond));
    } else {
      g.string("condition", "");
    }
    if (g.has("origin"))
      c.origin = read_vector<Dim>(g, "origin");
    else
      g.number("origin", 0.0);
    // Disordered lattices (particles/lattice.hpp, LatticeJitter): below half a spacing.
    c.jitter.fraction = g.non_negative("jitter", 0.0);
    g.require(c.jitter.fraction < kMaxJitterFraction, "jitter",
              fmt::format("must lie in [0, {}) spacings (at half a spacing a particle can reach its "
                          "neighbour's place or a face), got {}",
                          kMaxJitterFraction, c.jitter.fraction));
    const std::int64_t seed = g.integer("jitter_seed", 0);
    g.require(seed >= 0, "jitter_seed", fmt::format("must be >= 0, got {}", seed));
    c.jitter.seed = static_cast<std::uint64_t>(seed);
    const auto blocks = g.tables("block");
    const auto particle_files = g.tables("particles");
    const auto polygons = g.tables("polygon");
    if (!blocks.empty() && !particle_files.empty()) {
      particle_files.front().fail("", "give either [[geometry.block]] or [[geometry.particles]], not both");
    }
    if (!polygons.empty() && (!blocks.empty() || !particle_files.empty())) {
      polygons.front().fail("", fmt::format("give either [[geometry.polygon]] or [[geometry.{}]], not both",
                                            blocks.empty() ? "particles" : "block"));
    }
    if (blocks.empty() && particle_files.empty() && polygons.empty()) {
      g.fail("block",
             "missing: the geometry needs at least one [[geometry.block]] (or [[geometry.polygon]], or "
             "[[geometry.particles]])");
    }
    if (!polygons.empty()) {
      // Polygon bodies (case/polygon_reader.hpp): discretised here, carried as particles with faces.
      if (c.jitter.fraction > 0.0)
        g.fail("jitter", "applies to lattices generated from [[geometry.block]], not to polygons");
      read_polygons<Dim>(g, polygons, c);
    }
    if (!particle_files.empty()) {
      particles_where = particle_files.front().where();
      if (c.jitter.fraction > 0.0) {
        g.fail("jitter", "applies to lattices generated from [[geometry.block]], not to particles from files");
      }
      c.imported = read_imported_particles<Dim>(doc, particle_files, c);
    }
    for (const io::Section& b : blocks) {
      Block<Dim> blk;
      blk.min = read_vector<Dim>(b, "min");
      blk.max = read_vector<Dim>(b, "max");
      blk.material = material_index(c.material_names, b, "material");
      blk.label = b.where();
      b.finish();
      c.blocks.push_back(blk);
    }
    g.finish();
    // Size guard: lattice coordinates within the lattice's integer range (case/size_limits.hpp),
    // before the lattice generator converts them.
    if (auto p = lattice_size_problem(c)) {
      if (p->block >= 0) blocks[static_cast<std::size_t>(p->block)].fail(p->key, p->message);
      g.fail(p->key, p->message);
    }
  }
  if (Dim == 1 && c.condition == BarCondition::uniaxial_stress) {
    // docs/cases.md Case 2: scalar sigma with zero lateral stresses; the wrapper gives the
    // elastic rate (lambda = 0, 2G = E), the bar speed and the source at (sxx, 0, 0).
    for (auto& m : c.materials) m = std::make_shared<UniaxialStressMaterial>(m);
  }

  // ---- kernel
  if (auto k = root.optional_table("kernel")) {
    const std::string type = k->string("type", "cubic_spline");
    if (type != "cubic_spline") k->fail("type", fmt::format("unknown kernel '{}' (known: cubic_spline)", type));
    c.h_over_dx = k->positive("h_over_dx", 1.2);
    k->require(c.h_over_dx >= 0.6 && c.h_over_dx <= 3.0, "h_over_dx",
               fmt::format("must lie in [0.6, 3] (a smaller support leaves particles without "
                           "neighbours), got {}",
                           c.h_over_dx));
    k->finish();
  }

  // ---- body force and damping
  if (auto b = root.optional_table("body_force")) {
    c.gravity = read_vector<Dim>(*b, "gravity");
    c.gravity_function = function_index(c, *b, "function");
    b->finish();
  }
  if (auto d = root.optional_table("damping")) {
    c.damping = d->non_negative("coefficient", 0.0);
    c.damping_until = d->non_negative("until", std::numeric_limits<double>::infinity());
    c.damping_until_kinetic_ratio = d->non_negative("until_kinetic_ratio", 0.0);
    d->require(c.damping_until_kinetic_ratio < 1.0, "until_kinetic_ratio",
               fmt::format("must lie in [0, 1) (a fraction of the peak kinetic energy), got {}",
                           c.damping_until_kinetic_ratio));
    c.damping_ratio_from = d->non_negative("kinetic_ratio_from", 0.0);
    c.damping_ratio_hold = d->non_negative("kinetic_ratio_hold", 0.0);
    d->finish();
  }

  // ---- boundary conditions
  for (const io::Section& b : root.tables("boundary")) c.boundaries.push_back(read_boundary<Dim>(b, c));

  // ---- initial state
  if (auto is = root.optional_table("initial_stress")) {
    const std::string type = is->string("type", "zero");
    if (type == "zero") {
      c.initial_stress = InitialStressKind::zero;
    } else if (type == "geostatic") {
      c.initial_stress = InitialStressKind::geostatic;
      if (is->has("K0")) {
        const double k0 = is->number("K0");
        is->require(k0 > 0.0 && k0 < 10.0, "K0", fmt::format("must lie in (0, 10), got {}", k0));
        c.k0 = k0;
      } else {
        is->number("K0", 0.0);
      }
      if (is->has("surface"))
        c.surface_level = is->number("surface");
      else
        is->number("surface", 0.0);
      if (c.gravity.norm() == 0.0) {
        is->fail("type", "a geostatic initial stress needs [body_force] gravity");
      }
    } else if (type == "uniform") {
      // A uniform initial stress, Pa (tension positive), e.g. an isotropic confinement.
      c.initial_stress = InitialStressKind::uniform;
      // The components a Dim-D state carries (kStressComponentNames order: xx, yy, zz, xy, yz, xz).
      const std::size_t count = Dim == 1 ? 3 : Dim == 2 ? 4 : 6;
      for (std::size_t i = 0; i < count; ++i)
        c.uniform_stress[i] = is->number(std::string(kStressComponentNames[i]), 0.0);
    } else {
      is->fail("type", fmt::format("unknown initial stress '{}' (known: zero, geostatic, uniform)", type));
    }
    is->finish();
  }
  // A single [initial_velocity] table (the whole body) or [[initial_velocity]] entries.
  if (root.has("initial_velocity")) {
    if (root.raw()["initial_velocity"].is_array_of_tables()) {
      for (const io::Section& iv : root.tables("initial_velocity"))
        c.initial_velocities.push_back(read_initial_velocity<Dim>(iv, c));
    } else {
      c.initial_velocities.push_back(read_initial_velocity<Dim>(root.table("initial_velocity"), c));
    }
  } else {
    root.optional_table("initial_velocity");  // mark as read
  }

  // ---- solver
  if (auto s = root.optional_table("solver")) {
    c.version = s->string("version", "v1");
    const auto known = scheme_names<Dim>();
    if (std::find(known.begin(), known.end(), c.version) == known.end()) {
      s->fail("version", fmt::format("unknown solver version '{}' (available: {})", c.version, fmt::join(known, ", ")));
    }
    // V3 pressure solve (method-notes §2.4 "Solver"): its keys in a dry scheme are an error, not
    // silently dropped (a case moved from V3 to V2 keeps no pressure option it seems to have).
    if (!find_scheme<Dim>(c.version)->pore_fluid) {
      for (const char* key : {"pressure_preconditioner", "pressure_tolerance", "pressure_max_iterations",
                              "pressure_deferred_correction", "pressure_divergence", "pressure_incremental",
                              "pressure_faces", "pressure_filter", "pressure_filter_gradient",
                              "pressure_odd_even_filter"}) {
        if (s->has(key)) {
          s->fail(key, fmt::format("a key of the pore-pressure solve, for solver.version = \"v3\"; this case is "
                                   "\"{}\" (dry): remove it",
                                   c.version));
        }
      }
    }
    const std::string pc = s->string("pressure_preconditioner", "jacobi");
    if (pc == "jacobi")
      c.fluid.incomplete_cholesky = false;
    else if (pc == "incomplete_cholesky")
      c.fluid.incomplete_cholesky = true;
    else
      s->fail("pressure_preconditioner",
              fmt::format("unknown preconditioner '{}' (known: jacobi, incomplete_cholesky)", pc));
    c.fluid.tolerance = s->positive("pressure_tolerance", 1e-8);
    s->require(c.fluid.tolerance < 1e-2, "pressure_tolerance", "must be < 1e-2");
    const std::int64_t max_iterations = s->integer("pressure_max_iterations", 2000);
    s->require(max_iterations >= 1 && max_iterations <= std::numeric_limits<int>::max(), "pressure_max_iterations",
               fmt::format("must lie in [1, {}], got {}", std::numeric_limits<int>::max(), max_iterations));
    c.fluid.max_iterations = static_cast<int>(max_iterations);
    c.fluid.deferred_correction = s->boolean("pressure_deferred_correction", true);
    using StorageRate = FluidSpec::StorageRate;
    const std::string divergence = s->string("pressure_divergence", "consistent");
    if (divergence == "consistent")
      c.fluid.storage_rate = StorageRate::consistent;
    else if (divergence == "nodes")
      c.fluid.storage_rate = StorageRate::nodes;
    else if (divergence == "stress_points")
      c.fluid.storage_rate = StorageRate::stress_points;
    else
      s->fail("pressure_divergence",
              fmt::format("unknown value '{}' (known: consistent, nodes, stress_points)", divergence));
    // The incremental projection is the default. With the stress points' pressure-free velocity
    // it is unstable (an undrained column blows up within 0.5 s), so there the default is the
    // non-incremental form and asking for both is an error; the consistent form is built on the
    // incremental one (method-notes eq. (2.4.20)) and needs it.
    const bool pressure_free = c.fluid.storage_rate == StorageRate::stress_points;
    c.fluid.incremental = s->boolean("pressure_incremental", !pressure_free);
    s->require(!(c.fluid.incremental && pressure_free), "pressure_incremental",
               "cannot be true with pressure_divergence = \"stress_points\" (the combination is unstable)");
    s->require(c.fluid.incremental || c.fluid.storage_rate != StorageRate::consistent, "pressure_incremental",
               "cannot be false with pressure_divergence = \"consistent\" (the default; it is built on the "
               "incremental projection): set pressure_divergence = \"nodes\" for the non-incremental form");
    const std::string faces = s->string("pressure_faces", "auto");
    if (faces == "auto")
      c.fluid.face_condition = FluidSpec::FaceCondition::automatic;
    else if (faces == "implicit")
      c.fluid.face_condition = FluidSpec::FaceCondition::implicit;
    else if (faces == "explicit")
      c.fluid.face_condition = FluidSpec::FaceCondition::explicit_p;
    else
      s->fail("pressure_faces", fmt::format("unknown value '{}' (known: auto, implicit, explicit)", faces));
    c.fluid.filter = s->number("pressure_filter", 0.0);
    s->require(c.fluid.filter >= 0.0 && c.fluid.filter <= 10.0, "pressure_filter",
               fmt::format("must lie in [0, 10] (a multiple of S_w dt/rho), got {}", c.fluid.filter));
    const std::string filter_gradient = s->string("pressure_filter_gradient", "quadratic_drained");
    if (filter_gradient == "quadratic_drained")
      c.fluid.filter_gradient = FluidSpec::FilterGradient::quadratic_drained;
    else if (filter_gradient == "quadratic")
      c.fluid.filter_gradient = FluidSpec::FilterGradient::quadratic;
    else if (filter_gradient == "linear")
      c.fluid.filter_gradient = FluidSpec::FilterGradient::linear;
    else
      s->fail("pressure_filter_gradient",
              fmt::format("unknown value '{}' (known: quadratic_drained, quadratic, linear)", filter_gradient));
    c.fluid.odd_even_filter = s->number("pressure_odd_even_filter", 1.0);
    s->require(c.fluid.odd_even_filter >= 0.0 && c.fluid.odd_even_filter <= 1.0, "pressure_odd_even_filter",
               fmt::format("must lie in [0, 1] (the fraction of the odd-even amplitude removed a step), got {}",
                           c.fluid.odd_even_filter));
    const std::string scheme = s->string("scheme", "staggered");
    if (scheme == "staggered")
      c.layout = ParticleLayout::staggered;
    else if (scheme == "collocated")
      c.layout = ParticleLayout::collocated;
    else
      s->fail("scheme", fmt::format("unknown scheme '{}' (known: staggered, collocated)", scheme));
    c.filter = s->boolean("filter", true);
    const std::string velocity_update = s->string("velocity_update", "hourglass");
    c.simple_velocity = velocity_update == "simple";
    c.hourglass = velocity_update == "hourglass";
    if (velocity_update == "taylor_galerkin") {
      c.simple_velocity = false;
      c.hourglass = false;
    } else if (!c.simple_velocity && !c.hourglass) {
      s->fail("velocity_update",
              fmt::format("unknown value '{}' (known: hourglass, simple, taylor_galerkin)", velocity_update));
    }
    // The simple scheme's weights and the nodal stress filter traded V2's stability against its
    // numerical viscosity case by case; the default step (method-notes §2.6) needs none of them.
    // They stay as setup fields for the tests and benchmarks that compare them.
    for (const char* retired : {"simple_weight", "simple_stress_weight", "stress_filter", "stress_filter_part"}) {
      if (s->has(retired)) {
        s->fail(retired,
                "retired: V2's default step (velocity_update = \"hourglass\", method-notes §2.6) controls the nodal "
                "modes without a stabilisation key; the thesis's simple scheme is velocity_update = \"simple\"");
      }
    }
    c.gradient_floor = s->number("gradient_floor", default_gradient_floor<Dim>(c.version));
    s->require(c.gradient_floor >= 0.0 && c.gradient_floor <= 0.5, "gradient_floor",
               fmt::format("must lie in [0, 0.5] (the smallest eigenvalue allowed for a row's gradient "
                           "renormalisation matrix, 1 inside a lattice; 0: off), got {}",
                           c.gradient_floor));
    const bool can_detect = c.version == "v2" && Dim >= 2;
    const std::string surface = s->string("free_surface", can_detect ? "detect" : "faces");
    if (surface == "detect") {
      s->require(can_detect, "free_surface",
                 "\"detect\" needs solver.version = \"v2\" in 2D or 3D (small-deformation schemes keep the "
                 "faces of the lattice, a 1D bar's ends are its surface)");
      c.detect_free_surface = true;
    } else if (surface == "faces") {
      c.detect_free_surface = false;
    } else {
      s->fail("free_surface", fmt::format("unknown value '{}' (known: detect, faces)", surface));
    }
    c.surface_refresh = s->number("surface_refresh", 0.1);
    s->require(c.surface_refresh >= 0.0 && c.surface_refresh <= 0.5, "surface_refresh",
               fmt::format("must lie in [0, 0.5] (a multiple of dx; 0 evaluates every node every step), got {}",
                           c.surface_refresh));
    if (s->has("surface_refresh")) {
      s->require(c.detect_free_surface, "surface_refresh",
                 "applies to the detected free surface (solver.free_surface = \"detect\", V2 in 2D/3D)");
    }
    c.surface_mirrors = s->boolean("surface_mirrors", false);
    if (s->has("surface_mirrors")) {
      s->require(c.detect_free_surface && Dim == 2, "surface_mirrors",
                 "applies to the detected free surface beside rigid bodies (solver.free_surface = \"detect\", "
                 "V2 in 2D)");
    }
    const std::string reseed = s->string("reseed", "off");
    if (reseed == "off")
      c.reseed = ReseedSetting::off;
    else if (reseed == "auto")
      c.reseed = ReseedSetting::automatic;
    else if (reseed == "periodic")
      c.reseed = ReseedSetting::periodic;
    else
      s->fail("reseed", fmt::format("unknown value '{}' (known: off, auto, periodic)", reseed));
    if (c.reseed != ReseedSetting::off) {
      s->require(c.version == "v2", "reseed", "re-seeding the stress points needs solver.version = \"v2\"");
      s->require(c.layout == ParticleLayout::staggered, "reseed", "re-seeding needs solver.scheme = \"staggered\"");
    }
    // "auto" checks often (a front can outrun its stress points within a few steps; Case 9 ran
    // to 12.9 s checking every 5 steps, 7.65 s every 20); "periodic" re-seeds every interval.
    c.reseed_interval = static_cast<long>(s->integer("reseed_interval", c.reseed == ReseedSetting::periodic ? 20 : 5));
    s->require(c.reseed_interval >= 1, "reseed_interval",
               fmt::format("must be at least 1 step, got {}", c.reseed_interval));
    c.reseed_fill = s->number("reseed_fill", 0.5);
    s->require(c.reseed_fill > 0.0 && c.reseed_fill <= 1.0, "reseed_fill",
               fmt::format("must lie in (0, 1] (a fraction of a cell), got {}", c.reseed_fill));
    c.reseed_distance = s->number("reseed_distance", 1.0);
    s->require(c.reseed_distance >= 0.5 && c.reseed_distance <= 2.0, "reseed_distance",
               fmt::format("must lie in [0.5, 2] (a multiple of dx; on the lattice a node's nearest stress point "
                           "is sqrt(d)/2 dx away), got {}",
                           c.reseed_distance));
    c.reseed_cover = s->number("reseed_cover", 0.45);
    s->require(c.reseed_cover >= 0.0 && c.reseed_cover < 0.5, "reseed_cover",
               fmt::format("must lie in [0, 0.5) (a fraction of dx from a cell's centre), got {}", c.reseed_cover));
    const std::string shift = s->string("shift", "off");
    if (shift == "off")
      c.shift = ShiftSetting::off;
    else if (shift == "auto")
      c.shift = ShiftSetting::automatic;
    else if (shift == "periodic")
      c.shift = ShiftSetting::periodic;
    else
      s->fail("shift", fmt::format("unknown value '{}' (known: off, auto, periodic)", shift));
    if (c.shift != ShiftSetting::off) {
      s->require(c.version == "v2" && c.detect_free_surface, "shift",
                 "shifting the nodes needs solver.version = \"v2\" with free_surface = \"detect\" (2D, 3D): "
                 "the surface keeps its place");
    }
    c.shift_interval = static_cast<long>(s->integer("shift_interval", 20));
    s->require(c.shift_interval >= 1, "shift_interval",
               fmt::format("must be at least 1 step, got {}", c.shift_interval));
    c.shift_strength = s->number("shift_strength", 0.01);
    s->require(c.shift_strength > 0.0 && c.shift_strength <= 0.1, "shift_strength",
               fmt::format("must lie in (0, 0.1] (beta of method-notes eq. 5.2.6), got {}", c.shift_strength));
    c.shift_distance = s->number("shift_distance", 0.5);
    s->require(c.shift_distance > 0.0 && c.shift_distance <= 1.0, "shift_distance",
               fmt::format("must lie in (0, 1] (a multiple of dx), got {}", c.shift_distance));
    const std::string sort = s->string("sort", "auto");
    if (sort == "auto") {
      c.sort = SortSetting::automatic;
    } else if (sort == "always") {
      c.sort = SortSetting::always;
    } else if (sort == "off") {
      c.sort = SortSetting::off;
    } else {
      s->fail("sort", fmt::format("unknown value '{}' (known: auto, always, off)", sort));
    }
    if (s->has("sort")) {
      s->require(c.version == "v2", "sort",
                 "sorting the particles needs solver.version = \"v2\" (fixed particles keep the lattice's order, "
                 "which their operators' shared rows rely on)");
    }
    // "auto" is on the fly: the nodal filters apply the weights the steps keep as they go.
    const std::string operators = s->string("operators", "auto");
    if (operators == "auto" || operators == "on_the_fly") {
      c.operators_on_the_fly = true;
    } else if (operators == "stored") {
      c.operators_on_the_fly = false;
    } else {
      s->fail("operators", fmt::format("unknown value '{}' (known: auto, on_the_fly, stored)", operators));
    }
    if (s->has("operators")) {
      s->require(c.version == "v2", "operators",
                 "the operators' storage is a choice of solver.version = \"v2\" (fixed particles store theirs "
                 "once, as shared rows)");
    }
    if (s->has("domain_min") || s->has("domain_max")) {
      if (!s->has("domain_min")) s->fail("domain_max", "needs solver.domain_min as well (the box's lower corner)");
      if (!s->has("domain_max")) s->fail("domain_min", "needs solver.domain_max as well (the box's upper corner)");
      s->require(c.version == "v2", "domain_min",
                 "a domain box needs solver.version = \"v2\" (only large deformation moves the particles)");
      const Vec<Dim> lo = read_vector<Dim>(*s, "domain_min"), hi = read_vector<Dim>(*s, "domain_max");
      for (int d = 0; d < Dim; ++d) {
        s->require(
            hi[d] > lo[d], "domain_max",
            fmt::format("must exceed domain_min in every component (axis {}: {} <= {})", kAxisNames[d], hi[d], lo[d]));
      }
      c.domain_box = std::array<Vec<Dim>, 2>{lo, hi};
      c.domain_where = s->where("domain_min");
    }
    c.filter_strength = s->number("filter_strength", 0.5);
    s->require(c.filter_strength > 0.0 && c.filter_strength <= 1.0, "filter_strength",
               fmt::format("must lie in (0, 1], got {}", c.filter_strength));
    const std::string coupling = s->string("source_coupling", "additive");
    if (coupling == "additive")
      c.coupling = SourceCoupling::additive;
    else if (coupling == "frozen_flux")
      c.coupling = SourceCoupling::frozen_flux;
    else
      s->fail("source_coupling", fmt::format("unknown source coupling '{}' (known: additive, frozen_flux)", coupling));
    s->finish();
  }

  // ---- rigid bodies (2D; in V2 with the detected free surface: a lattice face keeps its
  // traction-free condition in global axes, which a contact would have to override)
  {
    const std::vector<io::Section> bodies = root.tables("body");
    if (!bodies.empty()) {
      if constexpr (Dim == 2) {
        // V1 and V3 (small deformation) take bodies that lie on a face of the lattice
        // (bodies/plates.hpp); the model checks their shape against the nodes.
        if (c.version == "v2" && !c.detect_free_surface) {
          root.fail("body",
                    "rigid bodies need solver.free_surface = \"detect\": on the lattice's faces the "
                    "traction-free condition would cancel the contact pressure");
        }
        for (std::size_t k = 0; k < bodies.size(); ++k) {
          c.bodies.push_back(case_reading::read_body(bodies[k], c, k));
          for (std::size_t j = 0; j < k; ++j) {
            if (c.bodies[j].name == c.bodies[k].name) {
              bodies[k].fail("name",
                             fmt::format("a second body named '{}' (names label bodies.csv)", c.bodies[k].name));
            }
          }
        }
      } else {
        root.fail("body", "rigid bodies are 2D only");
      }
    }
  }

  // Particles from files without their faces lie on no face: nothing would make their surface
  // traction-free but its detection (docs/case-format.md, "Particles from files").
  if (c.imported && !c.imported->faces_given && !c.detect_free_surface) {
    throw InputError(
        fmt::format("{}: particles from files without the face columns lie on no lattice face, so their "
                    "traction-free surface must be detected: use solver.version = \"v2\" in 2D with "
                    "solver.free_surface = \"detect\" (its default), or give the nodes' faces (face_-x, face_+x, ...)",
                    particles_where));
  }

  // ---- V3: the pore fluid (docs/case-format.md, "Saturated soil (V3)")
  const bool saturated = find_scheme<Dim>(c.version)->pore_fluid;
  if (!c.polygons.empty()) {
    if (saturated) {
      g.fail("polygon",
             "polygon bodies are not available with solver.version = \"v3\" yet (the pore-pressure "
             "conditions act on faces normal to an axis only)");
    }
    const auto& conditions = c.imported->boundary.condition;
    const bool inclined =
        std::any_of(conditions.begin(), conditions.end(), [](FaceCondition f) { return f != FaceCondition::axes; });
    if (inclined && c.version == "v2" && !c.detect_free_surface) {
      g.fail("polygon",
             "a polygon with edges normal to no axis needs solver.free_surface = \"detect\" in V2 "
             "(its geometric normals hold in the initial configuration only)");
    }
  }
  if (auto f = root.optional_table("fluid")) {
    if (!saturated) f->fail("porosity", "a [fluid] table needs solver.version = \"v3\"");
    FluidSpec& fl = c.fluid;
    fl.porosity = f->positive("porosity");
    f->require(fl.porosity < 1.0, "porosity", fmt::format("must lie in (0, 1), got {}", fl.porosity));
    fl.density = f->positive("density");
    fl.bulk_modulus = f->positive("bulk_modulus");
    fl.grain_bulk_modulus = f->non_negative("grain_bulk_modulus", 0.0);
    fl.conductivity = f->number("conductivity");
    f->require(fl.conductivity >= 0.0, "conductivity", "must be >= 0 (m/s)");
    fl.gravity = f->positive("gravity", 9.81);
    fl.saturation = f->positive("saturation", 1.0);
    f->require(fl.saturation <= 1.0, "saturation", fmt::format("must lie in (0, 1], got {}", fl.saturation));
    fl.initial_pore_pressure = f->number("initial_pore_pressure", 0.0);
    // The material density is the mixture density; the implied grain density must be physical.
    for (std::size_t m = 0; m < c.materials.size(); ++m) {
      const double rho = c.materials[m]->density();
      const double rho_s = (rho - fl.porosity * fl.density) / (1.0 - fl.porosity);
      f->require(rho_s >= fl.density, "density",
                 fmt::format("material '{}': the mixture density {} kg/m^3 with porosity {} and fluid "
                             "density {} kg/m^3 implies a grain density of {:.4g} kg/m^3, lighter than "
                             "the fluid (the material density is the MIXTURE density n rho_f + (1-n) rho_s)",
                             c.material_names[m], rho, fl.porosity, fl.density, rho_s));
    }
    f->finish();
  } else if (saturated) {
    root.fail("fluid", "missing: solver.version = \"v3\" needs a [fluid] table");
  }
  for (const auto& b : c.boundaries) {
    if (b.traction && c.version != "v1") {
      throw InputError(fmt::format("{}: a traction on a polygon edge needs solver.version = \"v1\"", b.where));
    }
    if (!saturated && (b.pore_pressure || b.impermeable)) {
      throw InputError(fmt::format("{}: pore_pressure / impermeable need solver.version = \"v3\"", b.where));
    }
  }

  // ---- size guard: particles and an estimate of the memory, from the blocks, before any
  // particle exists (case/size_limits.hpp; StaggeredModel checks again with the exact counts).
  {
    const SizeEstimate e = estimate_size(c, saturated);
    if (auto p = memory_problem(c, saturated, e.nodes, e.stress_points, e.lattice_cells)) g.fail(p->key, p->message);
  }

  // ---- time
  {
    const io::Section t = root.table("time");
    c.end_time = t.positive("end");
    const bool has_cfl = t.has("cfl"), has_dt = t.has("dt");
    if (has_cfl && has_dt) t.fail("dt", "give either cfl or dt, not both");
    if (has_dt) {
      c.dt = t.positive("dt");
      t.number("cfl", 0.0);
    } else {
      c.cfl = t.positive("cfl", 0.5);
      t.number("dt", 0.0);
    }
    // method-notes §0.3 item 4: reject C > kMaxCourant here, where the key's line is known (the
    // schemes check again for setups built in code, without a line).
    const TimeStep step = time_step_from(c.dx, max_wave_speed(c.materials), c.cfl, c.dt);
    if (step.courant > kMaxCourant) {
      t.fail(has_dt ? "dt" : "cfl",
             fmt::format("the Courant number c dt/dx = {:.3f} exceeds {} (c = {:.4g} m/s, dx = {} "
                         "m); the scheme is unstable beyond it (method-notes §0.3 item 4)",
                         step.courant, kMaxCourant, step.wave_speed, c.dx));
    }
    // V2: the step from the current state (method-notes §4.3, eq. (4.3.3)).
    const std::string rule = t.string("dt_rule", "fixed");
    if (rule == "current") {
      t.require(c.version == "v2", "dt_rule",
                fmt::format("\"current\" follows moving particles and needs solver.version = \"v2\" (this case is "
                            "\"{}\"; its particles do not move, so its step is fixed)",
                            c.version));
      t.require(!has_dt, "dt_rule", "\"current\" sets the step from time.cfl: give time.cfl, not time.dt");
      c.dt_from_current_state = true;
    } else if (rule != "fixed") {
      t.fail("dt_rule", fmt::format("unknown rule '{}' (\"fixed\" or \"current\")", rule));
    }
    // Size guard: the number of steps, before the run (case/size_limits.hpp).
    c.max_steps = t.number("max_steps", kDefaultMaxSteps);
    t.require(c.max_steps >= 1.0 && c.max_steps <= kMaxStepsCeiling, "max_steps",
              fmt::format("must lie in [1, {:.0e}] steps, got {}", kMaxStepsCeiling, c.max_steps));
    const std::string dt_text =
        has_dt ? std::string("time.dt")
               : fmt::format("C = {} times dx = {} m over c = {:.4g} m/s, the fastest wave speed of the materials",
                             *c.cfl, c.dx, step.wave_speed);
    if (auto p = step_count_problem(c.end_time, step.dt, c.max_steps, dt_text)) t.fail(p->key, p->message);
    t.finish();
  }

  // ---- output and probes
  if (auto o = root.optional_table("output")) {
    c.output_interval = o->non_negative("interval", 0.0);
    // The run advances the next frame time by the interval until it passes the clock: an
    // interval far below the step would take that loop end / interval rounds (and stall once
    // the interval is below the clock's rounding), so it is bounded like the step count.
    o->require(c.output_interval == 0.0 || c.end_time / c.output_interval <= c.max_steps, "interval",
               fmt::format("{} s gives {:.3g} frame times over time.end = {} s, more than time.max_steps = {:.4g}; "
                           "use 0 (first and last frames), or at least the time step for a frame every step",
                           c.output_interval, c.end_time / c.output_interval, c.end_time, c.max_steps));
    if (o->has("times")) {
      c.output_times = o->numbers("times");
      std::sort(c.output_times.begin(), c.output_times.end());
      if (!c.output_times.empty()) {
        o->require(c.output_times.front() >= 0.0, "times",
                   fmt::format("snapshot times must be >= 0 s, got {}", c.output_times.front()));
      }
      // Snapshot times past the end cannot be written. A warning, not an error: shortening a run
      // with --set time.end=... is the usual quick look at a case, and must not need its
      // snapshot list edited too.
      std::vector<double> late;
      for (const double t : c.output_times) {
        if (t > c.end_time) late.push_back(t);
      }
      if (!late.empty()) {
        c.warnings.push_back(fmt::format(
            "{}: {} of the snapshot times ({} s) {} past time.end = {} s and will not be "
            "written",
            o->where("times"), late.size(), fmt::join(late, ", "), late.size() == 1 ? "is" : "are", c.end_time));
      }
    } else {
      o->number("times", 0.0);
    }
    c.output_elements = o->boolean("elements", true);
    if (o->has("checkpoint_interval"))
      c.checkpoint_interval = o->non_negative("checkpoint_interval", 0.0);
    else
      o->number("checkpoint_interval", 0.0);
    const std::int64_t every = o->integer("probe_every", 1);
    o->require(every >= 1 && every <= std::numeric_limits<int>::max(), "probe_every",
               fmt::format("must lie in [1, {}], got {}", std::numeric_limits<int>::max(), every));
    c.probe_every = static_cast<int>(every);
    o->finish();
  }
  for (const io::Section& p : root.tables("probe")) c.probes.push_back(read_probe<Dim>(p, c));
  root.finish();
  for (const std::string& w : c.warnings) std::cerr << "warning: " << w << "\n";
  return c;
}

template CaseSetup<1> read_case<1>(const CaseDocument&);
template CaseSetup<2> read_case<2>(const CaseDocument&);
template CaseSetup<3> read_case<3>(const CaseDocument&);

}  // namespace rktsph
