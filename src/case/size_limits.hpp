#pragma once
// Size guards (docs/case-format.md, "Size limits"): the lattice, the particle count, an estimate
// of the memory and the number of time steps, checked before anything is allocated or run.
//
// Each check returns the problem (the key it is about and the message) instead of throwing, so
// that the case reader can raise it at the key's line and StaggeredModel, for cases built in
// code, without one.
#include <cstdint>
#include <optional>
#include <string>

#include "case/case_setup.hpp"

namespace rktsph {

/// The most steps time.max_steps may allow (the step counter and the clock stay exact far beyond).
inline constexpr double kMaxStepsCeiling = 1.0e15;
/// A block corner may lie at most this many spacings from geometry.origin along an axis, so that
/// lattice coordinates, and their differences, fit the lattice's int indices.
inline constexpr double kMaxLatticeCoordinate = 5.0e8;
/// Particles of one set: the particle index is a 32-bit integer.
inline constexpr double kMaxParticles = 2147483647.0;

/// A failed size check: the key it concerns, relative to the table named by `table` ("geometry",
/// "time", or "geometry.block" with `block` >= 0), and the message.
struct SizeProblem {
  std::string table;
  int block = -1;
  std::string key;
  std::string message;
  /// The dotted key, e.g. "geometry.spacing" or "geometry.block[1].max".
  std::string full_key() const;
};

/// Upper bounds of a case's particle counts, from its blocks alone (no lattice built): the sum
/// over the blocks, capped by the blocks' bounding box (exact when blocks do not overlap).
struct SizeEstimate {
  double nodes = 0.0;
  double stress_points = 0.0;
  double lattice_cells = 0.0;  // cells of the bounding box (the lattice's cell-material array)
  double bytes = 0.0;          // estimated peak memory of the run
};

/// Estimated peak memory per node (a node and its stress point, fields, operators and set-up
/// relations), bytes, measured on the thesis cases (docs/case-format.md, "Size limits").
double bytes_per_node(int dim, bool saturated);
/// Physical memory of this machine, bytes (sysconf); 0 when unknown.
double physical_memory_bytes();

/// Lattice coordinates of every block corner within kMaxLatticeCoordinate of the origin.
template <int Dim>
std::optional<SizeProblem> lattice_size_problem(const CaseSetup<Dim>& c);

template <int Dim>
SizeEstimate estimate_size(const CaseSetup<Dim>& c, bool saturated);

/// Particles within kMaxParticles and the estimated memory within `memory_bytes` (the
/// machine's, by default), for the given particle counts.
template <int Dim>
std::optional<SizeProblem> memory_problem(const CaseSetup<Dim>& c, bool saturated, double nodes, double stress_points,
                                          double lattice_cells, double memory_bytes = physical_memory_bytes());

/// The number of steps end / dt within max_steps. `dt_text` says where dt comes from.
std::optional<SizeProblem> step_count_problem(double end_time, double dt, double max_steps, const std::string& dt_text);

/// "2.3 GiB", "512 MiB".
std::string bytes_text(double bytes);

}  // namespace rktsph
