// `rktsph lem`: the limit-equilibrium reference of a case (docs/output.md, "lem.json").
#include "app/lem_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "lem/lem_case.hpp"
#include "rktsph/version.hpp"

namespace rktsph {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json ring_json(const std::vector<lem::Point>& ring) {
  nlohmann::json a = nlohmann::json::array();
  for (const lem::Point& p : ring) a.push_back({p.x, p.y});
  return a;
}

}  // namespace

int run_lem(const LemOptions& o) {
  const CaseDocument doc = load_case_document(o.case_file, o.overrides);
  const lem::LemProblem problem = lem::read_lem_problem(doc);
  const std::string out_dir =
      o.out_dir.empty() ? (std::filesystem::path("out") / (std::filesystem::path(o.case_file).stem().string() + "-lem")).string()
                        : o.out_dir;
  const auto& g = problem.geometry;
  lem::SearchOptions search = o.search;
  if (!o.centre_box.empty()) {
    const auto& b = o.centre_box;
    if (b.size() != 4 || !(b[1] > b[0]) || !(b[3] > b[2]) ||
        !std::all_of(b.begin(), b.end(), [](double v) { return std::isfinite(v); })) {
      throw InputError("--centres: give X0 X1 Y0 Y1 in m with X1 > X0 and Y1 > Y0");
    }
    search.x_lo = b[0];
    search.x_hi = b[1];
    search.y_lo = b[2];
    search.y_hi = b[3];
  }
  const lem::SearchResult r = lem::search_critical_circle(g, problem.soil, search);
  std::filesystem::create_directories(out_dir);

  nlohmann::json j;
  j["version"] = kVersion;
  j["git_revision"] = kGitRevision;
  j["case_file"] = o.case_file;
  j["title"] = problem.title;
  j["method"] = "Bishop simplified, circular slip surfaces (method-notes §9)";
  j["soil"] = {{"material", problem.material_name},
               {"model", problem.model},
               {"cohesion_Pa", problem.soil.cohesion},
               {"friction_angle_deg", problem.soil.friction_angle * kDeg},
               {"density_kg_per_m3", problem.density},
               {"gravity_m_per_s2", problem.gravity},
               {"unit_weight_N_per_m3", problem.soil.unit_weight}};
  nlohmann::json bodies = nlohmann::json::array();
  for (const lem::Body& b : g.bodies()) {
    nlohmann::json holes = nlohmann::json::array();
    for (const auto& h : b.holes) holes.push_back(ring_json(h));
    nlohmann::json body = {{"name", b.name}, {"outer", ring_json(b.outer)}, {"holes", holes}};
    if (b.soil) {
      body["material"] = b.material;
      body["cohesion_Pa"] = b.soil->cohesion;
      body["friction_angle_deg"] = b.soil->friction_angle * kDeg;
      body["unit_weight_N_per_m3"] = b.soil->unit_weight;
    }
    bodies.push_back(body);
  }
  j["bodies"] = bodies;
  j["layered"] = g.layered();  // true: "soil" is the first body's; each body gives its own
  nlohmann::json rigid = nlohmann::json::array();
  for (const lem::RigidRegion& rr : g.rigid_regions()) {
    rigid.push_back({{"name", rr.name},
                     {"x", {finite_or_null(rr.lo[0]), finite_or_null(rr.hi[0])}},
                     {"y", {finite_or_null(rr.lo[1]), finite_or_null(rr.hi[1])}}});
  }
  j["rigid_regions"] = rigid;
  j["notes"] = problem.notes;
  // A critical centre within one first-level spacing of the box's edge may have a lower one
  // outside it (the refinements can leave the box, but only by a few spacings).
  const double hx = (r.x_hi - r.x_lo) / (o.search.grid - 1), hy = (r.y_hi - r.y_lo) / (o.search.grid - 1);
  const bool on_edge = r.found() && (r.circle.centre.x < r.x_lo + hx || r.circle.centre.x > r.x_hi - hx ||
                                     r.circle.centre.y < r.y_lo + hy || r.circle.centre.y > r.y_hi - hy);
  j["search"] = {{"grid_per_axis", o.search.grid},
                 {"levels", o.search.levels},
                 {"radii_per_centre", o.search.radii},
                 {"slices", o.search.bishop.slices},
                 {"m_alpha_floor", o.search.bishop.m_alpha_floor},
                 {"first_box", {{"x", {r.x_lo, r.x_hi}}, {"y", {r.y_lo, r.y_hi}}}},
                 {"final_centre_spacing_m", {r.final_spacing_x, r.final_spacing_y}},
                 {"circles_evaluated", r.circles_evaluated},
                 {"circles_admissible", r.circles_valid},
                 {"critical_centre_near_first_box_edge", on_edge}};
  nlohmann::json grid = nlohmann::json::array();
  for (const lem::GridPoint& p : r.first_grid) {
    grid.push_back({p.centre.x, p.centre.y, finite_or_null(p.factor), p.radius});
  }
  j["first_grid"] = grid;  // [x_c, y_c, least F over the radii (null: none admissible), its radius]
  if (!r.found()) {
    j["factor_of_safety"] = nullptr;
    std::ofstream(std::filesystem::path(out_dir) / "lem.json") << j.dump(1) << '\n';
    std::cerr << fmt::format("error: {}: no admissible slip circle in the search box (x in [{}, {}] m, y in [{}, {}] m); "
                             "see {}/lem.json\n",
                             o.case_file, r.x_lo, r.x_hi, r.y_lo, r.y_hi, out_dir);
    return kExitUnstable;
  }
  const lem::CircleResult& c = r.critical;
  j["factor_of_safety"] = c.factor;
  j["fellenius_factor_same_circle"] = c.fellenius;
  j["circle"] = {{"centre", {r.circle.centre.x, r.circle.centre.y}}, {"radius", r.circle.radius}};
  j["entry"] = {c.entry.x, c.entry.y};
  j["exit"] = {c.exit.x, c.exit.y};
  j["sliding_direction"] = c.direction < 0 ? "-x" : "+x";
  j["iterations"] = c.iterations;
  j["m_alpha_limited_slices"] = c.limited_slices;
  nlohmann::json slices = nlohmann::json::array();
  for (const lem::Slice& s : c.slices) {
    slices.push_back({{"x", s.x},
                      {"width", s.width},
                      {"base_y", s.base_y},
                      {"height", s.height},
                      {"alpha_deg", s.alpha * kDeg},
                      {"weight_N_per_m", s.weight},
                      {"base_cohesion_Pa", s.cohesion},
                      {"base_friction_angle_deg", std::atan(s.tan_phi) * kDeg},
                      {"base_length", s.base_length},
                      {"m_alpha", s.m_alpha},
                      {"m_alpha_limited", s.m_alpha_limited}});
  }
  j["slices"] = slices;
  const std::string json_file = (std::filesystem::path(out_dir) / "lem.json").string();
  std::ofstream(json_file) << j.dump(1) << '\n';
  if (!o.quiet) {
    fmt::print("lem: F = {:.4f} (Bishop simplified, {} slices; Fellenius on the same circle {:.4f})\n"
               "     critical circle: centre ({:.3f}, {:.3f}) m, radius {:.3f} m; entry ({:.3f}, {:.3f}), exit ({:.3f}, "
               "{:.3f})\n     {} circles evaluated, {} admissible; final centre spacing {:.2g} x {:.2g} m\n",
               c.factor, o.search.bishop.slices, c.fellenius, r.circle.centre.x, r.circle.centre.y, r.circle.radius,
               c.entry.x, c.entry.y, c.exit.x, c.exit.y, r.circles_evaluated, r.circles_valid, r.final_spacing_x,
               r.final_spacing_y);
    if (g.layered()) {
      for (const lem::Body& b : g.bodies()) {
        if (!b.soil) continue;
        fmt::print("     {}: '{}', c = {:.4g} kPa, phi = {:.4g} deg, gamma = {:.4g} kN/m^3\n", b.name, b.material,
                   b.soil->cohesion / 1e3, b.soil->friction_angle * kDeg, b.soil->unit_weight / 1e3);
      }
    }
    for (const std::string& n : problem.notes) fmt::print("note: {}\n", n);
    if (on_edge) fmt::print("warning: the critical centre lies near the edge of the first search box\n");
    fmt::print("wrote {}\n", json_file);
  }
  if (o.plot) {
    const std::string script = std::string(RKTSPH_SOURCE_DIR) + "/scripts/plot_lem.py";
    const bool have_mpl = std::filesystem::exists("/usr/bin/python3") &&
                          std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
    const std::string png = (std::filesystem::path(out_dir) / "lem.png").string();
    if (!have_mpl) {
      fmt::print("note: /usr/bin/python3 with matplotlib not found; no plot written\n");
    } else if (std::system(fmt::format("/usr/bin/python3 '{}' '{}' '{}'", script, json_file, png).c_str()) != 0) {
      fmt::print("note: the plot script failed; lem.json is complete\n");
    } else if (!o.quiet) {
      fmt::print("wrote {}\n", png);
    }
  }
  return 0;
}

}  // namespace rktsph
