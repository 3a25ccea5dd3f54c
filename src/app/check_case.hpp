#pragma once
// `rktsph check CASE...`: read every case file as `run` (or `material-point`) would, build its
// particles, operators and solver, and say what a run would do, without running it or writing
// anything (docs/case-format.md, "Checking a case").
#include <string>
#include <vector>

namespace rktsph {

struct CheckOptions {
  std::vector<std::string> files;
  std::vector<std::string> overrides;  // --set, applied to every file
  int threads = 0;                     // --threads for the estimate (0: the run's default)
  bool estimate = true;                // time a few steps and the plastic return (--no-estimate: off)
};

/// One line per file ("ok" with the particles, the step and the steps to time.end, or the error
/// naming file, line and key), and for a sound case a second line estimating the run time from a
/// few trial steps (at most 20, or a second), with the bound that holds if every particle flows
/// plastically (from timed backward-Euler returns of each Perzyna material, method-notes §2.5).
/// Returns 0 when every file is sound, 2 when any is not.
int check_cases(const CheckOptions& options);

}  // namespace rktsph
