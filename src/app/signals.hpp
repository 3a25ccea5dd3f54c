#pragma once
// SIGINT and SIGTERM during a run (docs/output.md, "Interrupted runs"): the first asks the run
// to stop after the current step (it then writes a frame, a checkpoint and its summary and
// exits with 128 + the signal); a second one ends the program at once, which leaves the output
// consistent because every file is written whole (io/output_files.hpp).
namespace rktsph {

/// Install the handlers (idempotent).
void install_stop_handlers();
/// The signal that asked the run to stop, or 0.
int stop_signal();

}  // namespace rktsph
