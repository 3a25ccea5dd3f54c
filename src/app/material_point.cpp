#include "app/material_point.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "rktsph/version.hpp"

namespace rktsph {

void write_path_csv(const std::string& file, const Material& material, const PathResult& r) {
  std::ofstream out(file);
  if (!out) throw InputError(fmt::format("cannot write {}", file));
  out << "t,exx,eyy,ezz,exy,sxx,syy,szz,sxy,p,q";
  for (const std::string& n : material.state_names()) out << ',' << n;
  out << '\n';
  for (const PathPoint& pt : r.points) {
    const Invariants inv = invariants(pt.stress);
    out << fmt::format(
        "{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},"
        "{:.10g},{:.10g}",
        pt.t, pt.strain[0], pt.strain[1], pt.strain[2], pt.strain[3], pt.stress[0], pt.stress[1], pt.stress[2],
        pt.stress[3], inv.p, inv.q);
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
    j["implicit_steps"] = r.implicit_steps;
    j["newton_iterations"] = r.newton_iterations;
    j["max_relaxation_rate_per_s"] = r.max_relaxation_rate;
    j["final"] = {{"t", last.t}, {"p", inv.p}, {"q", inv.q}};
    for (std::size_t i = 0; i < last.state.size(); ++i) {
      j["final"][c.material->state_names()[i]] = last.state[i];
    }
    std::ofstream(std::filesystem::path(out_dir) / "summary.json") << j.dump(2) << '\n';
    fmt::print(
        "material point: {} along {}: {} steps, {} RK4 sub-steps, {} backward-Euler steps; final p = {:.6g} Pa, "
        "q = {:.6g} Pa\nwrote {}\n",
        c.material->model(), c.path_type, r.steps, r.substeps, r.implicit_steps, inv.p, inv.q, csv);
    if (c.plot) {
      const std::string script = std::string(RKTSPH_SOURCE_DIR) + "/scripts/plot_material_point.py";
      const bool have_mpl = std::filesystem::exists("/usr/bin/python3") &&
                            std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
      if (!have_mpl) {
        fmt::print("note: /usr/bin/python3 with matplotlib not found; no plot written\n");
      } else {
        const std::string png = (std::filesystem::path(out_dir) / "path.png").string();
        const std::string cmd =
            fmt::format("/usr/bin/python3 '{}' '{}' '{}' --strain {}", script, csv, png, c.plot_strain);
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
