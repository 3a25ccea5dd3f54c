#include "case/size_limits.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace rktsph {

std::string SizeProblem::full_key() const {
  const std::string t = block >= 0 ? fmt::format("{}[{}]", table, block) : table;
  return t.empty() ? key : fmt::format("{}.{}", t, key);
}

double bytes_per_node(int dim, bool saturated) {
  // Peak resident memory over nodes, measured with /usr/bin/time on one step of the thesis
  // cases at two or three spacings (the slope, so the fixed start-up cost is left out), rounded
  // up by about 20 %: V1 1D 450 B (case 2), V1 2D 490 B (elastic block) to 590 B (case 6,
  // viscoplastic); V3 1D 1.9 kB (case 13), V3 2D 8.6 to 9.9 kB (cases 16 and 17: the pressure
  // Laplacian with its mirror images and the PCG). 3D is not measured: 4 times 2D.
  if (saturated) return dim == 1 ? 2500.0 : dim == 2 ? 12000.0 : 48000.0;
  return dim == 1 ? 600.0 : dim == 2 ? 700.0 : 2800.0;
}

double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0.0;
  return static_cast<double>(pages) * static_cast<double>(page);
}

std::string bytes_text(double bytes) {
  constexpr double kKiB = 1024.0, kMiB = kKiB * 1024.0, kGiB = kMiB * 1024.0, kTiB = kGiB * 1024.0;
  if (bytes >= kTiB) return fmt::format("{:.3g} TiB", bytes / kTiB);
  if (bytes >= kGiB) return fmt::format("{:.3g} GiB", bytes / kGiB);
  if (bytes >= kMiB) return fmt::format("{:.3g} MiB", bytes / kMiB);
  return fmt::format("{:.3g} kiB", bytes / kKiB);
}

namespace {

std::string block_name(std::size_t b) { return fmt::format("geometry.block[{}]", b); }

}  // namespace

template <int Dim>
std::optional<SizeProblem> lattice_size_problem(const CaseSetup<Dim>& c) {
  const double dx = c.dx;
  std::array<double, Dim> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b < c.blocks.size(); ++b) {
    const Block<Dim>& blk = c.blocks[b];
    for (std::size_t d = 0; d < Dim; ++d) {
      const int i = static_cast<int>(d);
      const double extent = (blk.max[i] - blk.min[i]) / dx;  // max < min: the lattice generator says so
      if (extent > kMaxLatticeCoordinate) {
        return SizeProblem{
            "geometry", -1, "spacing",
            fmt::format("a spacing of {} m makes {} {:.3g} cells long along {} (from {} to {} m); the "
                        "lattice holds at most {:.0e} cells per axis: use a larger spacing",
                        dx, block_name(b), extent, kAxisNames[d], blk.min[i], blk.max[i], kMaxLatticeCoordinate)};
      }
      for (const auto& [key, x] : {std::pair{"min", blk.min[i]}, std::pair{"max", blk.max[i]}}) {
        const double t = (x - c.origin[i]) / dx;
        if (!(std::abs(t) <= kMaxLatticeCoordinate)) {
          return SizeProblem{"geometry.block", static_cast<int>(b), key,
                             fmt::format("the corner coordinate {} m along {} lies {:.3g} spacings ({} m) from "
                                         "geometry.origin ({} m); the lattice holds at most {:.0e} cells per axis",
                                         x, kAxisNames[d], std::abs(t), dx, c.origin[i], kMaxLatticeCoordinate)};
        }
        lo[d] = std::min(lo[d], t);
        hi[d] = std::max(hi[d], t);
      }
    }
  }
  for (std::size_t d = 0; d < Dim; ++d) {
    if (!c.blocks.empty() && !(hi[d] - lo[d] <= kMaxLatticeCoordinate)) {
      return SizeProblem{"geometry", -1, "spacing",
                         fmt::format("with a spacing of {} m the blocks together span {:.3g} cells along {}; the "
                                     "lattice holds at most {:.0e} cells per axis: use a larger spacing",
                                     dx, hi[d] - lo[d], kAxisNames[d], kMaxLatticeCoordinate)};
    }
  }
  return std::nullopt;
}

template <int Dim>
SizeEstimate estimate_size(const CaseSetup<Dim>& c, bool saturated) {
  SizeEstimate e;
  std::array<double, Dim> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const Block<Dim>& blk : c.blocks) {
    double cells = 1.0, nodes = 1.0;
    for (std::size_t d = 0; d < Dim; ++d) {
      const int i = static_cast<int>(d);
      const double a = std::round((blk.min[i] - c.origin[i]) / c.dx);
      const double z = std::round((blk.max[i] - c.origin[i]) / c.dx);
      const double n = std::max(0.0, z - a);
      cells *= n;
      nodes *= n + 1.0;
      lo[d] = std::min(lo[d], a);
      hi[d] = std::max(hi[d], z);
    }
    e.stress_points += cells;
    e.nodes += nodes;
  }
  if (!c.blocks.empty()) {
    double box_cells = 1.0, box_nodes = 1.0;
    for (std::size_t d = 0; d < Dim; ++d) {
      const double n = std::max(0.0, hi[d] - lo[d]);
      box_cells *= n;
      box_nodes *= n + 1.0;
    }
    e.lattice_cells = box_cells;
    e.stress_points = std::min(e.stress_points, box_cells);
    e.nodes = std::min(e.nodes, box_nodes);
  }
  if (c.imported) {  // particles from files: their counts, and no lattice
    e.nodes = static_cast<double>(c.imported->nodes.size());
    e.stress_points = static_cast<double>(c.imported->stress_points.size());
  }
  e.bytes = e.nodes * bytes_per_node(Dim, saturated) + e.lattice_cells * static_cast<double>(sizeof(int));
  return e;
}

template <int Dim>
std::optional<SizeProblem> memory_problem(const CaseSetup<Dim>& c, bool saturated, double nodes, double stress_points,
                                          double lattice_cells, double memory_bytes) {
  const double most = std::max(nodes, stress_points);
  if (!(most <= kMaxParticles)) {
    return SizeProblem{"geometry", -1, "spacing",
                       fmt::format("a spacing of {} m gives {:.3g} nodes and {:.3g} stress points, more than the "
                                   "{:.0f} particles one set can hold: use a larger spacing",
                                   c.dx, nodes, stress_points, kMaxParticles)};
  }
  const double per_node = bytes_per_node(Dim, saturated);
  const double bytes = nodes * per_node + lattice_cells * static_cast<double>(sizeof(int));
  if (memory_bytes > 0.0 && !(bytes <= memory_bytes)) {
    return SizeProblem{
        "geometry", -1, "spacing",
        fmt::format("a spacing of {} m gives {:.3g} nodes and {:.3g} stress points; the run would need about {} "
                    "(an estimate: {:.0f} bytes per node for a {}D {} case), more than this machine's {} of "
                    "memory: use a larger spacing",
                    c.dx, nodes, stress_points, bytes_text(bytes), per_node, Dim,
                    saturated ? "saturated (V3)" : "dry (V1)", bytes_text(memory_bytes))};
  }
  return std::nullopt;
}

std::optional<SizeProblem> step_count_problem(double end_time, double dt, double max_steps,
                                              const std::string& dt_text) {
  const double steps = end_time / dt;
  if (steps <= max_steps) return std::nullopt;
  const std::string allow =
      steps <= kMaxStepsCeiling
          ? fmt::format("a longer run must allow it with time.max_steps (>= {:.4g})", std::ceil(steps))
          : fmt::format("no run may take more than {:.0e} steps (the most time.max_steps allows)", kMaxStepsCeiling);
  return SizeProblem{"time", -1, "end",
                     fmt::format("an end time of {} s is {:.4g} steps of dt = {:.4g} s ({}), more than time.max_steps "
                                 "= {:.4g}; {}",
                                 end_time, steps, dt, dt_text, max_steps, allow)};
}

template std::optional<SizeProblem> lattice_size_problem<1>(const CaseSetup<1>&);
template std::optional<SizeProblem> lattice_size_problem<2>(const CaseSetup<2>&);
template std::optional<SizeProblem> lattice_size_problem<3>(const CaseSetup<3>&);
template SizeEstimate estimate_size<1>(const CaseSetup<1>&, bool);
template SizeEstimate estimate_size<2>(const CaseSetup<2>&, bool);
template SizeEstimate estimate_size<3>(const CaseSetup<3>&, bool);
template std::optional<SizeProblem> memory_problem<1>(const CaseSetup<1>&, bool, double, double, double, double);
template std::optional<SizeProblem> memory_problem<2>(const CaseSetup<2>&, bool, double, double, double, double);
template std::optional<SizeProblem> memory_problem<3>(const CaseSetup<3>&, bool, double, double, double, double);

}  // namespace rktsph
