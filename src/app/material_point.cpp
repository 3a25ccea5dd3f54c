#include "app/material_point.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "core/error.hpp"
#include "io/section.hpp"
#include "rktsph/version.hpp"

namespace rktsph {

namespace {

// Apply one "a.b.c=value" override. Scalars are rebuilt as fresh nodes so that error messages
// say "value set on the command line" instead of quoting a line of the override text.
void apply_override(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError(fmt::format("override '{}': expected key=value, e.g. material.E=2.5e7",
                                 assignment));
  }
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  toml::table* t = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    toml::node* next = t->get(parts[i]);
    if (next == nullptr) {
      t->insert(parts[i], toml::table{});
      next = t->get(parts[i]);
    }
    t = next->as_table();
    if (t == nullptr) {
      throw InputError(fmt::format("override '{}': '{}' is not a table", assignment, parts[i]));
    }
  }
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", text}};
  }
  const toml::node& v = *parsed.get("v");
  if (auto i = v.value_exact<std::int64_t>()) {
    t->insert_or_assign(parts.back(), *i);
  } else if (auto d = v.value_exact<double>()) {
    t->insert_or_assign(parts.back(), *d);
  } else if (auto b = v.value_exact<bool>()) {
    t->insert_or_assign(parts.back(), *b);
  } else if (auto s = v.value_exact<std::string>()) {
    t->insert_or_assign(parts.back(), *s);
  } else {
    t->insert_or_assign(parts.back(), v);
  }
}

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
          st->fail(kStressComponentNames[i],
                   "a component is either strain- or stress-controlled, not both");
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
  const std::int64_t every = s.integer("output_every", 1);
  s.require(every >= 1, "output_every", fmt::format("must be >= 1, got {}", every));
  path.output_every = static_cast<int>(every);
  s.finish();
  return path;
}

}  // namespace

MaterialPointCase load_material_point_case(const std::string& case_file,
                                           const std::vector<std::string>& overrides) {
  if (!std::filesystem::exists(case_file)) {
    throw InputError(fmt::format("{}: no such case file", case_file));
  }
  toml::table root;
  try {
    root = toml::parse_file(case_file);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}, line {}: {}", case_file, e.source().begin.line,
                                 e.description()));
  }
  for (const std::string& o : overrides) apply_override(root, o);
  const io::Section top(root, "", std::make_shared<const std::string>(case_file));

  MaterialPointCase c;
  const io::Section mat = top.table("material");
  c.material = create_material(mat);
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

void write_path_csv(const std::string& file, const Material& material, const PathResult& r) {
  std::ofstream out(file);
  if (!out) throw InputError(fmt::format("cannot write {}", file));
  out << "t,exx,eyy,ezz,exy,sxx,syy,szz,sxy,p,q";
  for (const std::string& n : material.state_names()) out << ',' << n;
  out << '\n';
  for (const PathPoint& pt : r.points) {
    const Invariants inv = invariants(pt.stress);
    out << fmt::format("{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},"
                       "{:.10g},{:.10g}",
                       pt.t, pt.strain[0], pt.strain[1], pt.strain[2], pt.strain[3], pt.stress[0],
                       pt.stress[1], pt.stress[2], pt.stress[3], inv.p, inv.q);
    for (double v : pt.state) out << fmt::format(",{:.10g}", v);
    out << '\n';
  }
}

int run_material_point(const std::string& case_file, const std::string& out_dir,
                       const std::vector<std::string>& overrides) {
  try {
    MaterialPointCase c = load_material_point_case(case_file, overrides);
    const PathResult r = integrate_path(*c.material, c.sigma0, c.path);
    std::filesystem::create_directories(out_dir);
    const std::string csv = (std::filesystem::path(out_dir) / "path.csv").string();
    write_path_csv(csv, *c.material, r);
    const PathPoint& last = r.points.back();
    const Invariants inv = invariants(last.stress);
    nlohmann::json j;
    j["version"] = kVersion;
    j["git_revision"] = kGitRevision;
    j["case_file"] = case_file;
    j["model"] = std::string(c.material->model());
    j["path_type"] = c.path_type;
    j["steps"] = r.steps;
    j["rk4_substeps"] = r.substeps;
    j["max_relaxation_rate_per_s"] = r.max_relaxation_rate;
    j["final"] = {{"t", last.t}, {"p", inv.p}, {"q", inv.q}};
    for (std::size_t i = 0; i < last.state.size(); ++i) {
      j["final"][c.material->state_names()[i]] = last.state[i];
    }
    std::ofstream(std::filesystem::path(out_dir) / "summary.json") << j.dump(2) << '\n';
    fmt::print("material point: {} along {}: {} steps, {} RK4 sub-steps; final p = {:.6g} Pa, "
               "q = {:.6g} Pa\nwrote {}\n",
               c.material->model(), c.path_type, r.steps, r.substeps, inv.p, inv.q, csv);
    if (c.plot) {
      const std::string script = std::string(RKTSPH_SOURCE_DIR) + "/scripts/plot_material_point.py";
      const bool have_mpl =
          std::filesystem::exists("/usr/bin/python3") &&
          std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
      if (!have_mpl) {
        fmt::print("note: /usr/bin/python3 with matplotlib not found; no plot written\n");
      } else {
        const std::string png = (std::filesystem::path(out_dir) / "path.png").string();
        const std::string cmd = fmt::format("/usr/bin/python3 '{}' '{}' '{}' --strain {}", script,
                                            csv, png, c.plot_strain);
        if (std::system(cmd.c_str()) != 0) {
          fmt::print("note: the plot script failed; path.csv is complete\n");
        } else {
          fmt::print("wrote {}\n", png);
        }
      }
    }
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "input error: %s\n", e.what());
    return 2;
  } catch (const SolverError& e) {
    std::fprintf(stderr, "solver error: %s\n", e.what());
    return 3;
  }
}

}  // namespace rktsph
