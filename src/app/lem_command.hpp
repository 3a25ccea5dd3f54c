#pragma once
// `rktsph lem CASE.toml [--out DIR]`: Bishop's simplified method with a search over circular
// slip surfaces on the case's bodies and soil (lem/bishop.hpp, method-notes §9); writes
// DIR/lem.json and, when /usr/bin/python3 has matplotlib, DIR/lem.png (scripts/plot_lem.py).
#include <string>
#include <vector>

#include "lem/bishop.hpp"

namespace rktsph {

struct LemOptions {
  std::string case_file;
  std::string out_dir;  // default out/<case name>-lem
  std::vector<std::string> overrides;
  lem::SearchOptions search;
  std::vector<double> centre_box;  // --centres X0 X1 Y0 Y1 (m), empty: the default box
  bool plot = true;
  bool quiet = false;
};

/// The whole command; input errors are thrown as InputError (exit status 2 in main). Returns 0,
/// or 3 when no admissible circle exists.
int run_lem(const LemOptions& options);

}  // namespace rktsph
