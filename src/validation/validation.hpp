#pragma once
// `rktsph validate`: run the thesis cases, compare them with their references (docs/cases.md) by
// code in this repository, write a report with plots, and fail if a criterion is not met.
#include <functional>
#include <string>
#include <vector>

namespace rktsph::validation {

struct Metric {
  std::string name;
  double value = 0.0;
  std::string relation;  // "<=" or ">=" ; empty for a reported figure with no tolerance
  double tolerance = 0.0;
  std::string unit;
  /// Non-empty for a documented deviation: a criterion known not to be met, with what was
  /// measured and why (or "open:" when the cause is not yet established). The report and
  /// docs/VALIDATION.md show it as not met; it does not fail the command, so that CI keeps
  /// guarding every other criterion. The tolerance itself is never changed.
  std::string known_deviation;
  bool pass() const {
    if (relation == "<=") return value <= tolerance;
    if (relation == ">=") return value >= tolerance;
    return true;
  }
};

inline Metric metric(std::string name, double value, std::string relation, double tolerance, std::string unit) {
  Metric m;
  m.name = std::move(name);
  m.value = value;
  m.relation = std::move(relation);
  m.tolerance = tolerance;
  m.unit = std::move(unit);
  return m;
}

struct CaseReport {
  std::string id;  // "01"
  std::string title;
  std::string reference;
  std::vector<Metric> metrics;
  std::vector<std::string> plots;  // PNG files relative to the report
  std::vector<std::string> notes;
  double seconds = 0.0;
  /// Every criterion met.
  bool passed() const {
    for (const auto& m : metrics) {
      if (!m.pass()) return false;
    }
    return true;
  }
  /// Every criterion met, except those with a documented known deviation.
  bool acceptable() const {
    for (const auto& m : metrics) {
      if (!m.pass() && m.known_deviation.empty()) return false;
    }
    return true;
  }
};

struct Options {
  bool full = false;  // docs/cases.md resolutions (else coarse, CI-sized)
  std::string out_dir = "validation";
  std::string cases_dir;          // where cases/thesis lives
  std::vector<std::string> only;  // case ids; empty = all
  bool plots = true;
  /// With full: one more halving of the finest spacing in the cases whose criterion is a
  /// convergence under refinement (Case 11's band width), reported beside the criterion.
  bool refine = false;
};

/// Run one validation case; writes CSV data and plots under out_dir/case<id>/.
using CaseRunner = std::function<CaseReport(const Options&, const std::string& case_dir)>;

CaseReport validate_case01(const Options& options, const std::string& case_dir);
CaseReport validate_case02(const Options& options, const std::string& case_dir);
CaseReport validate_case03(const Options& options, const std::string& case_dir);
CaseReport validate_case04(const Options& options, const std::string& case_dir);
CaseReport validate_case05(const Options& options, const std::string& case_dir);
CaseReport validate_case06(const Options& options, const std::string& case_dir);
CaseReport validate_case07(const Options& options, const std::string& case_dir);
CaseReport validate_case08(const Options& options, const std::string& case_dir);
CaseReport validate_case09(const Options& options, const std::string& case_dir);
CaseReport validate_case10(const Options& options, const std::string& case_dir);
CaseReport validate_case11(const Options& options, const std::string& case_dir);
CaseReport validate_case12(const Options& options, const std::string& case_dir);
CaseReport validate_case13(const Options& options, const std::string& case_dir);
CaseReport validate_case14(const Options& options, const std::string& case_dir);
CaseReport validate_case15(const Options& options, const std::string& case_dir);
CaseReport validate_case16(const Options& options, const std::string& case_dir);
CaseReport validate_case17(const Options& options, const std::string& case_dir);
/// Case 18: the collapse of a frictional column of aspect ratio 0.5 (docs/cases.md).
CaseReport validate_case18(const Options& options, const std::string& case_dir);
/// Mandel's problem with a force-driven rigid plate (cases/examples/mandel_2d.toml).
CaseReport validate_mandel(const Options& options, const std::string& case_dir);

/// Run the selected cases and write out_dir/report.md. Returns 0 if all pass, 1 otherwise.
int run_validation(const Options& options);

/// Run /usr/bin/python3 on a plotting script; returns false (with a note) if unavailable.
bool run_plot_script(const std::string& script, const std::string& data_dir, std::string& note);

}  // namespace rktsph::validation
