#pragma once
// The time loop of `rktsph run` and `rktsph resume` (docs/output.md): a Simulation marched to
// the end time with its output streams (frames, probes, energies), checkpoints, the summary
// and the response to SIGINT / SIGTERM. A resumed loop continues every stream from the
// checkpoint as if the run had never stopped.
#include <filesystem>
#include <optional>
#include <string>

#include "app/run_case.hpp"
#include "case/case_reader.hpp"
#include "io/state_archive.hpp"

namespace rktsph {

struct LoopInput {
  RunOptions options;
  CaseDocument document;              // the case as run (after --set)
  std::filesystem::path out;          // output folder
  const io::StateArchive* checkpoint = nullptr;  // resume from this state; null: a fresh run
};

/// Run to the end (or to a stop) and return the exit status: 0 completed, 3 unstable,
/// 4 a write failed, 128 + signal when interrupted; InputError escapes for bad input.
template <int Dim>
int run_loop(const LoopInput& input);

}  // namespace rktsph
