#pragma once
// Particle sets read from CSV files (geometry.particles, docs/case-format.md "Particles from
// files"): one file for the nodes and one for the stress points, each with the header
// x,y[,z],volume,material[,density] (columns in any order) and one particle per line.
//
// Every error is an InputError that names the CSV file, its line and its column, after the
// case file's key that names the CSV ("case.toml, line 9, key 'geometry.particles[0].nodes':
// nodes.csv, line 14, column 'volume': must be > 0, got -0.01").
#include <string>
#include <vector>

#include "particles/particle_set.hpp"

namespace rktsph {

/// The materials a particle file may name, and their densities (kg/m^3): the density of a
/// particle whose file has no density column.
struct ParticleFileMaterials {
  std::vector<std::string> names;
  std::vector<double> densities;
};

/// Append the particles of the CSV file `path` to `set`; returns the line of the file each came
/// from. `where` starts every error message (the case file's key, e.g. Section::where("nodes"));
/// `label` is the file as the messages name it (the path as the case gave it).
template <int Dim>
std::vector<long> read_particle_file(const std::string& path, const std::string& label, const std::string& where,
                                     const ParticleFileMaterials& materials, ParticleSet<Dim>& set);

/// The first two particles of `set` closer than `tolerance` (m), as indices, or {-1, -1}.
template <int Dim>
std::pair<Index, Index> coincident_particles(const ParticleSet<Dim>& set, double tolerance);

}  // namespace rktsph
