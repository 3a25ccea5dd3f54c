#pragma once
// Checkpoint files: a StateArchive (io/state_archive.hpp) in HDF5, the format of the field
// (h5py, h5dump and ParaView read it), one dataset per key. The file is written under a
// temporary name, synced and renamed, so a checkpoint on disk is always complete; it records
// its format version, the program's version and a checksum of every value, and reading it
// refuses a foreign, damaged or incompatible file with a clear message (InputError).
#include <string>

#include "io/state_archive.hpp"

namespace rktsph::io {

/// The format of the checkpoint files this program writes and reads.
// 2: the sets' fingerprints as made from the case; 3: energy.csv gained its column
// kinetic_stress_points (a run of format 2 resumed would append rows longer than its header).
inline constexpr int kCheckpointFormat = 3;

void write_checkpoint(const std::string& path, const StateArchive& archive);
StateArchive read_checkpoint(const std::string& path);

}  // namespace rktsph::io
