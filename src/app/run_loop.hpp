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
#include "case/case_setup.hpp"
#include "io/field_catalogue.hpp"
#include "io/state_archive.hpp"
#include "particles/particle_set.hpp"

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

/// The node a probe follows: the nearest to its position as the case made the nodes. A probe
/// farther than half a cell's diagonal from every node lies outside the body: InputError naming
/// the probe's file and line. (`rktsph run` and `rktsph check`.)
template <int Dim>
Index probe_node(const ProbeSpec& spec, const ParticleSet<Dim>& nodes, double dx);

/// A probe's field by name from the nodes' catalogue; InputError listing the names available.
template <int Dim>
io::ScalarField probe_field(const ProbeSpec& spec, const std::string& field, const io::FieldCatalogue<Dim>& nodes);

}  // namespace rktsph
