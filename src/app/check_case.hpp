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
};

/// One line per file ("ok" with the particles, the step and the steps to time.end, or the error
/// naming file, line and key). Returns 0 when every file is sound, 2 when any is not.
int check_cases(const CheckOptions& options);

}  // namespace rktsph
