// Reading a material-point file (docs/materials.md, "Material-point runs"): the material
// table, the initial stress and the load path, every error with file, line and key.
#include "case/material_point_reader.hpp"

#include <cmath>
#include <filesystem>
#include <limits>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "case/case_reader.hpp"
#include "case/material_reader.hpp"
#include "core/error.hpp"
#include "io/section.hpp"

namespace rktsph {

namespace {

Sym6 read_sym6(const io::Section& s) {
  Sym6 out{};
  for (std::size_t i = 0; i < 6; ++i) out[i] = s.number(kStressComponentNames[i], 0.0);
  s.finish();
  return out;
}

LoadPath read_path(const io::Section& s, std::string& type, std::string& plot_strain) {
  type = s.string("type");
  LoadPath path;
  plot_strain = "yy";
  auto axial = [&] { return s.number("axial_strain_rate"); };
  if (type == "drained_triaxial") {
    path = LoadPath::drained_triaxial(axial());
  } else if (type == "undrained_triaxial") {
    path = LoadPath::undrained_triaxial(axial());
  } else if (type == "oedometric") {
    path = LoadPath::oedometric(axial());
  } else if (type == "plane_strain_compression") {
    path = LoadPath::plane_strain_compression(axial());
  } else if (type == "simple_shear") {
    path = LoadPath::simple_shear(s.number("shear_strain_rate"));
    plot_strain = "xy";
  } else if (type == "strain_rate") {
    const Sym6 eps = read_sym6(s.table("strain_rate"));
    Sym6 sig{};
    std::array<bool, 6> stress_set{};
    if (auto st = s.optional_table("stress_rate")) {
      for (std::size_t i = 0; i < 6; ++i) {
        stress_set[i] = st->has(kStressComponentNames[i]);
        if (stress_set[i] && s.table("strain_rate").has(kStressComponentNames[i])) {
          st->fail(kStressComponentNames[i], "a component is either strain- or stress-controlled, not both");
        }
      }
      sig = read_sym6(*st);
    }
    double biggest = -1.0;
    for (std::size_t i = 0; i < 6; ++i) {
      path.control[i] = stress_set[i] ? Control::stress : Control::strain;
      path.rate[i] = stress_set[i] ? sig[i] : eps[i];
      if (!stress_set[i] && std::abs(eps[i]) > biggest) {
        biggest = std::abs(eps[i]);
        plot_strain = std::string(kStressComponentNames[i]);
      }
    }
  } else {
    s.fail("type", fmt::format("unknown path type '{}' (known: strain_rate, drained_triaxial, "
                               "undrained_triaxial, oedometric, plane_strain_compression, "
                               "simple_shear)",
                               type));
  }
  path.duration = s.positive("duration");
  path.dt = s.positive("dt", path.duration / 1000.0);
  // Size guards: the steps of the path and the rows kept in memory and written to path.csv.
  const double steps = std::ceil(path.duration / path.dt);
  s.require(steps <= kDefaultMaxSteps, "dt",
            fmt::format("duration / dt = {} s / {} s = {:.4g} steps, more than {:.0e}: use a larger dt", path.duration,
                        path.dt, steps, kDefaultMaxSteps));
  const std::int64_t every = s.integer("output_every", 1);
  s.require(every >= 1 && every <= std::numeric_limits<int>::max(), "output_every",
            fmt::format("must lie in [1, {}], got {}", std::numeric_limits<int>::max(), every));
  path.output_every = static_cast<int>(every);
  constexpr double kMaxRows = 1.0e7;
  s.require(steps / static_cast<double>(every) <= kMaxRows, "output_every",
            fmt::format("{} steps with a row every {} make {:.4g} rows of path.csv, more than {:.0e}: raise "
                        "output_every",
                        steps, every, steps / static_cast<double>(every), kMaxRows));
  s.finish();
  return path;
}

}  // namespace

MaterialPointCase load_material_point_case(const std::string& case_file, const std::vector<std::string>& overrides) {
  if (!std::filesystem::exists(case_file)) {
    throw InputError(fmt::format("{}: no such case file", case_file));
  }
  toml::table root;
  try {
    root = toml::parse_file(case_file);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}, line {}: {}", case_file, e.source().begin.line, e.description()));
  }
  for (const std::string& o : overrides) apply_override(root, o, case_file);
  const io::Section top(root, "", std::make_shared<const std::string>(case_file));

  MaterialPointCase c;
  const io::Section mat = top.table("material");
  c.material = read_material(mat);
  mat.finish();
  if (auto init = top.optional_table("initial")) {
    if (auto st = init->optional_table("stress")) c.sigma0 = read_sym6(*st);
    init->finish();
  }
  c.path = read_path(top.table("path"), c.path_type, c.plot_strain);
  if (auto out = top.optional_table("output")) {
    c.plot = out->boolean("plot", true);
    out->finish();
  }
  top.finish();
  // Initial history variables can fail on the initial stress (an OCR with tensile p').
  std::vector<double> k(static_cast<std::size_t>(c.material->state_size()));
  try {
    c.material->initial_state(c.sigma0, k.data());
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", top.where("initial"), e.what()));
  }
  return c;
}

}  // namespace rktsph
