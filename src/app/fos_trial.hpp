#pragma once
// One trial of `rktsph fos`, run in process (docs/fos.md, "What a trial is"): the case at a
// factor F, already written into its document (app/fos_setup.hpp), built as a Simulation and
// marched step by step while an observer follows the monitored node. A strength-reduction trial
// is decided by the hold rule (app/fos_criterion.hpp) and stopped as soon as it collapses; a
// load-factor trial runs to time.end and is classified afterwards on its histories by the rule of
// CASES.md §1.3. Nothing is written but the histories kept here and, if asked, the final state's
// nodes as one VTU file.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/fos_criterion.hpp"
#include "app/fos_setup.hpp"
#include "case/case_reader.hpp"

namespace rktsph::fos {

/// A trial's histories, sampled as `rktsph run` samples its probes (every output.probe_every
/// steps) and its energies (about 2000 times a run), and at its last step.
struct TrialHistory {
  std::vector<double> t;   // s
  std::vector<double> uc;  // m: u . direction at the monitored node
  std::vector<double> energy_t;               // s
  std::vector<double> kinetic;                // J: the nodes' kinetic energy
  std::vector<double> kinetic_stress_points;  // J: the stress points'
  std::vector<double> plastic;                // J: the plastic dissipation so far
};

struct TrialSpec {
  const CaseDocument* document = nullptr;  // the case at this factor
  Monitor monitor;
  /// The hold rule of a strength-reduction trial (its end is the trial's end); none: the trial
  /// runs to the case's time.end and is classified afterwards (the load factor).
  std::optional<HoldRule> hold;
  int threads = 1;
  std::filesystem::path frame;  // the final state's nodes as VTU; empty: none
};

struct TrialResult {
  int exit_code = 0;    // 0 ran to its end or to its decision, 3 the solver stopped, 128 + signal
  std::string message;  // the solver's, when it stopped
  TrialHistory history;
  HoldOutcome hold_outcome = HoldOutcome::running;
  HoldMeasures hold;
  long steps = 0;
  double end_time = 0.0;  // s: the simulated time reached
  double seconds = 0.0;   // wall-clock
};

/// Run one trial. InputError escapes for a document the reader refuses (a reduced value out of
/// range); the solver's SolverError is a result (exit_code 3, message).
TrialResult run_trial(const TrialSpec& spec);

}  // namespace rktsph::fos
