#pragma once
// Particle sets read from CSV files (geometry.particles, docs/case-format.md "Particles from
// files"): one file for the nodes and one for the stress points, each with the header
// x,y[,z],volume,material[,density] (columns in any order) and one particle per line; a node
// file may also give each node's faces (face_-x, face_+x, ...).
//
// Every error is an InputError that names the CSV file, its line and its column, after the
// case file's key that names the CSV ("case.toml, line 9, key 'geometry.particles[0].nodes':
// nodes.csv, line 14, column 'volume': must be > 0, got -0.01").
#include <string>
#include <vector>

#include "particles/lattice.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

/// The materials a particle file may name, and their densities (kg/m^3): the density of a
/// particle whose file has no density column.
struct ParticleFileMaterials {
  std::vector<std::string> names;
  std::vector<double> densities;
};

/// The name of the node-file column of the face with outward normal -e_d (side 2d) or +e_d
/// (side 2d + 1): "face_-x", "face_+x", "face_-y", ...
std::string face_column_name(std::size_t side);

/// Append the particles of the CSV file `path` to `set`; returns the line of the file each came
/// from. `where` starts every error message (the case file's key, e.g. Section::where("nodes"));
/// `label` is the file as the messages name it (the path as the case gave it). A node file
/// (`faces` given) may also have the face columns, all of them or none: a node's area of each
/// face of the body, 0 where it is not on it (BoundaryNodes, the lattice's faces); the nodes on a
/// face are appended to `faces`, and `faces_given` says whether the file had the columns.
template <int Dim>
std::vector<long> read_particle_file(const std::string& path, const std::string& label, const std::string& where,
                                     const ParticleFileMaterials& materials, ParticleSet<Dim>& set,
                                     BoundaryNodes<Dim>* faces = nullptr, bool* faces_given = nullptr);

/// The first two particles of `set` closer than `tolerance` (m), as indices, or {-1, -1}.
template <int Dim>
std::pair<Index, Index> coincident_particles(const ParticleSet<Dim>& set, double tolerance);

}  // namespace rktsph
