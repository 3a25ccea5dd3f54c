#pragma once
#include <string>
#include <vector>

namespace rktsph {

struct RunOptions {
  std::string case_file;
  std::string out_dir;  // empty: out/<case name>
  std::vector<std::string> overrides;
  int threads = 0;     // 0: OpenMP default
  bool quiet = false;  // no progress line
};

/// Run a case end to end and write its output folder. Returns the exit status:
/// 0 done, 2 bad input, 3 the run went unstable (last good output kept).
int run_case(const RunOptions& options);

}  // namespace rktsph
