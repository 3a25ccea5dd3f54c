#pragma once
// `rktsph run CASE` and `rktsph resume DIR` (docs/output.md).
#include <string>
#include <vector>

namespace rktsph {

struct RunOptions {
  std::string case_file;
  std::string out_dir;  // empty: out/<case name>; for resume: the folder of the interrupted run
  std::vector<std::string> overrides;
  int threads = 0;     // 0: OpenMP default
  bool quiet = false;  // no progress line
};

/// Run a case end to end and write its output folder. Returns the exit status: 0 done, 2 bad
/// input, 3 the run went unstable, 4 an output file could not be written, 128 + signal when
/// stopped by SIGINT / SIGTERM (a checkpoint is then written); the output so far is kept.
int run_case(const RunOptions& options);

/// Continue the run in options.out_dir from its checkpoint; only time.end and output.* may be
/// overridden. Same exit statuses.
int resume_case(const RunOptions& options);

}  // namespace rktsph
