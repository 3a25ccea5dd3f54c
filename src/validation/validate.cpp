#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <fmt/format.h>

#include "core/error.hpp"
#include "rktsph/version.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

bool run_plot_script(const std::string& script, const std::string& data_dir, std::string& note) {
  const fs::path path = fs::path(RKTSPH_SOURCE_DIR) / "scripts" / script;
  if (!fs::exists("/usr/bin/python3")) {
    note = "plots skipped: /usr/bin/python3 not found (apt-get install python3-matplotlib)";
    return false;
  }
  const std::string cmd = fmt::format("/usr/bin/python3 '{}' '{}'", path.string(), data_dir);
  if (std::system(cmd.c_str()) != 0) {
    note = fmt::format("plots failed: '{}' returned an error (is python3-matplotlib installed?)", cmd);
    return false;
  }
  return true;
}

int run_validation(const Options& opt) {
  const std::vector<std::pair<std::string, CaseRunner>> cases = {
      {"01", validate_case01}, {"02", validate_case02}, {"03", validate_case03}, {"04", validate_case04},
      {"05", validate_case05}, {"06", validate_case06}, {"07", validate_case07}, {"08", validate_case08},
      {"09", validate_case09}, {"10", validate_case10},
      {"11", validate_case11}, {"12", validate_case12},
      {"13", validate_case13}, {"14", validate_case14}, {"15", validate_case15}, {"16", validate_case16},
      {"17", validate_case17},
      // Beyond the thesis: Case 18 (cases/thesis/18_granular_column_2d.toml, docs/cases.md) and
      // Mandel's problem (cases/examples/).
      {"18", validate_case18},
      {"mandel", validate_mandel},
  };
  fs::create_directories(opt.out_dir);
  std::vector<CaseReport> reports;
  for (const auto& [id, runner] : cases) {
    if (!opt.only.empty() && std::find(opt.only.begin(), opt.only.end(), id) == opt.only.end()) continue;
    const std::string dir = (fs::path(opt.out_dir) / ("case" + id)).string();
    fs::create_directories(dir);
    std::cerr << fmt::format("validating case {} ...\n", id);
    const auto t0 = std::chrono::steady_clock::now();
    CaseReport r = runner(opt, dir);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cerr << fmt::format("case {}: {} ({:.1f} s)\n", id,
                             r.passed() ? "PASS" : (r.acceptable() ? "PASS except known deviations" : "FAIL"),
                             r.seconds);
    for (const auto& m : r.metrics) {
      std::cerr << fmt::format(
          "  [{}] {} = {:.4g}{}{}\n",
          m.relation.empty() ? "info" : (m.pass() ? " ok " : (m.known_deviation.empty() ? "FAIL" : "KNOWN")), m.name,
          m.value, m.unit.empty() ? "" : " " + m.unit,
          m.relation.empty() ? "" : fmt::format(" (tolerance {} {:.4g})", m.relation, m.tolerance));
    }
    reports.push_back(std::move(r));
  }
  if (reports.empty()) {
    std::cerr << "no validation case matched the selection\n";
    return 2;
  }

  std::ofstream md(fs::path(opt.out_dir) / "report.md");
  md << fmt::format("# rktsph validation report\n\nrktsph {} ({}), mode: {}.\n\n", kVersion, kGitRevision,
                    opt.full ? "full (docs/cases.md resolutions)" : "quick (coarse resolutions for CI)");
  md << "| case | status | run time |\n|---|---|---|\n";
  int failed = 0;
  for (const auto& r : reports) {
    md << fmt::format("| {} {} | {} | {:.1f} s |\n", r.id, r.title,
                      r.passed() ? "pass" : (r.acceptable() ? "pass except known deviations (see below)" : "**FAIL**"),
                      r.seconds);
    if (!r.acceptable()) ++failed;
  }
  for (const auto& r : reports) {
    md << fmt::format("\n## Case {} — {}\n\nReference: {}.\n\n", r.id, r.title, r.reference);
    md << "| metric | value | tolerance | status |\n|---|---|---|---|\n";
    for (const auto& m : r.metrics) {
      md << fmt::format(
          "| {} | {:.4g}{} | {} | {} |\n", m.name, m.value, m.unit.empty() ? "" : " " + m.unit,
          m.relation.empty() ? "reported" : fmt::format("{} {:.4g}", m.relation, m.tolerance),
          m.relation.empty()
              ? "—"
              : (m.pass()
                     ? "pass"
                     : (m.known_deviation.empty() ? "**FAIL**" : "**not met** (known: " + m.known_deviation + ")")));
    }
    if (!r.notes.empty()) {
      md << "\n";
      for (const auto& n : r.notes) md << "- " << n << "\n";
    }
    for (const auto& p : r.plots) md << fmt::format("\n![{}]({})\n", p, p);
  }
  std::cerr << fmt::format("report: {}\n", (fs::path(opt.out_dir) / "report.md").string());
  return failed == 0 ? 0 : 1;
}

}  // namespace rktsph::validation
