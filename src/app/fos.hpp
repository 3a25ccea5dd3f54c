#pragma once
// `rktsph fos CASE`: the factor of safety by strength reduction (docs/fos.md, method-notes §10),
// or with fos.mode = "load" the load factor of the collapse load. Each trial is the case run
// with its strengths divided by a factor F, or its named loads multiplied by F
// (app/fos_setup.hpp), in its own output folder, and classified stable / collapse by the rule of
// docs/cases.md §1.3 on the monitored displacement; the search (app/fos_search.hpp) brackets and
// bisects F.
#include <string>
#include <vector>

namespace rktsph {

/// The search ended without a factor of safety: the unreduced case does not stand, or the
/// bracket did not close within the allowed trials (the trials are kept).
inline constexpr int kExitNoFactor = 5;

struct FosOptions {
  std::string case_file;
  std::string out_dir;  // empty: out/<case name>_fos
  std::vector<std::string> overrides;
  std::string solver;         // empty: the case's own solver.version (default v1); else v1, v2, v3
  double tolerance = 0.0;     // > 0: overrides fos.tolerance
  int max_trials = 0;         // > 0: overrides fos.max_trials
  int jobs = 0;               // trials at once; 0: one per thread
  int threads = 0;            // threads in all, shared by the trials at once (0: as main resolved)
  bool quiet = false;         // no progress lines
  bool plot = true;           // scripts/plot_fos.py
};

/// Run the search and write fos.json (and fos_uc.png). Exit status: 0 a factor was found, 2 bad
/// input (including a material with no strength to reduce and a monitor off the body), 4 an
/// output could not be written, 5 (kExitNoFactor) no factor, 128 + signal when stopped.
int run_fos(const FosOptions& options);

}  // namespace rktsph
