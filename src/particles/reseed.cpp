#include "particles/reseed.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph {

namespace {

// A cell's lattice index packed in 21 bits per axis (offset so that negative indices pack):
// x fastest in the ordering of the keys, as the generator orders its cells.
constexpr int kBits = 21;
constexpr std::int64_t kOffset = std::int64_t{1} << (kBits - 1);
constexpr std::int64_t kMask = (std::int64_t{1} << kBits) - 1;

template <int Dim>
std::int64_t pack(const std::array<std::int64_t, Dim>& c) {
  std::int64_t key = 0;
  for (int d = Dim - 1; d >= 0; --d) {
    const std::int64_t v = c[static_cast<std::size_t>(d)] + kOffset;
    if (v < 0 || v > kMask) throw SolverError("re-seeding: a node lies more than 2^20 cells from the lattice origin");
    key = (key << kBits) | v;
  }
  return key;
}

template <int Dim>
std::array<std::int64_t, Dim> unpack(std::int64_t key) {
  std::array<std::int64_t, Dim> c{};
  for (int d = 0; d < Dim; ++d) {
    c[static_cast<std::size_t>(d)] = (key & kMask) - kOffset;
    key >>= kBits;
  }
  return c;
}

// One node's share of one cell (eq. (5.2.1)).
template <int Dim>
struct Deposit {
  std::int64_t cell;
  int material;
  double volume, mass;
  Vec<Dim> moment;      // volume times the node's position
  bool covers = false;  // a node lies within options.cover * dx of the cell's centre
};

}  // namespace

template <int Dim>
ReseedResult reseed_stress_points(const ParticleSet<Dim>& nodes, const Vec<Dim>& origin, const ReseedOptions& options,
                                  ParticleSet<Dim>& stress_points, std::int64_t& next_global_id) {
  if (!(options.dx > 0.0)) throw SolverError("re-seeding: the lattice spacing must be positive");
  ReseedResult result;
  result.before = stress_points.size();
  double mass_before = 0.0;
  for (Index e = 0; e < stress_points.owned(); ++e) mass_before += stress_points.mass(e);

  // Eq. (5.2.1): each node's volume and mass spread on the 2^Dim cell centres around it with
  // the multilinear (cloud-in-cell) weights.
  constexpr int kCorners = 1 << Dim;
  std::vector<Deposit<Dim>> deposits;
  deposits.reserve(static_cast<std::size_t>(nodes.owned()) * kCorners);
  for (Index i = 0; i < nodes.owned(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    std::array<std::int64_t, Dim> base{};
    std::array<double, Dim> frac{};
    for (int d = 0; d < Dim; ++d) {
      const double s = (nodes.position[iu][d] - origin[d]) / options.dx - 0.5;
      const double b = std::floor(s);
      base[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(b);
      frac[static_cast<std::size_t>(d)] = s - b;
    }
    for (int corner = 0; corner < kCorners; ++corner) {
      std::array<std::int64_t, Dim> c = base;
      double w = 1.0;
      for (int d = 0; d < Dim; ++d) {
        const auto du = static_cast<std::size_t>(d);
        const bool up = ((corner >> d) & 1) != 0;
        c[du] += up ? 1 : 0;
        w *= up ? frac[du] : 1.0 - frac[du];
      }
      if (w <= 0.0) continue;
      deposits.push_back({pack<Dim>(c), nodes.material[iu], w * nodes.volume[iu], w * nodes.mass(i),
                          w * nodes.volume[iu] * nodes.position[iu]});
    }
    if (options.cover > 0.0) {
      // The cell whose centre the node is nearest, if within the cover window (per axis).
      std::array<std::int64_t, Dim> c{};
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        const double s = (nodes.position[iu][d] - origin[d]) / options.dx;
        const double cell = std::floor(s);
        c[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(cell);
        inside = inside && std::abs(s - cell - 0.5) < options.cover;
      }
      if (inside) deposits.push_back({pack<Dim>(c), nodes.material[iu], 0.0, 0.0, Vec<Dim>::Zero(), true});
    }
  }
  // The old stress points by cell: a new cell takes the material of the nearest old stress
  // point (the nodes cannot tell it at an interface between materials, where each node holds
  // one of them), within the cell's neighbours; else the material that deposited the most.
  std::vector<std::pair<std::int64_t, Index>> old_cells;
  old_cells.reserve(static_cast<std::size_t>(stress_points.owned()));
  for (Index e = 0; e < stress_points.owned(); ++e) {
    std::array<std::int64_t, Dim> c{};
    for (int d = 0; d < Dim; ++d) {
      c[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(
          std::floor((stress_points.position[static_cast<std::size_t>(e)][d] - origin[d]) / options.dx));
    }
    old_cells.emplace_back(pack<Dim>(c), e);
  }
  std::sort(old_cells.begin(), old_cells.end());
  auto nearest_old_material = [&](const std::array<std::int64_t, Dim>& cell, const Vec<Dim>& centre) {
    int material = -1;
    double best = std::numeric_limits<double>::infinity();
    constexpr int kNeighbours = Dim == 1 ? 3 : (Dim == 2 ? 9 : 27);
    for (int k = 0; k < kNeighbours; ++k) {
      std::array<std::int64_t, Dim> c = cell;
      int rest = k;
      for (int d = 0; d < Dim; ++d) {
        c[static_cast<std::size_t>(d)] += rest % 3 - 1;
        rest /= 3;
      }
      const std::int64_t key = pack<Dim>(c);
      auto it = std::lower_bound(old_cells.begin(), old_cells.end(), std::make_pair(key, Index{0}));
      for (; it != old_cells.end() && it->first == key; ++it) {
        const auto eu = static_cast<std::size_t>(it->second);
        const double r2 = (stress_points.position[eu] - centre).squaredNorm();
        if (r2 < best || (r2 == best && stress_points.material[eu] < material)) {
          best = r2;
          material = stress_points.material[eu];
        }
      }
    }
    return material;
  };

  // Deterministic sums: by cell (x fastest), then material, then the deposits' own values.
  std::sort(deposits.begin(), deposits.end(), [](const Deposit<Dim>& a, const Deposit<Dim>& b) {
    if (a.cell != b.cell) return a.cell < b.cell;
    if (a.material != b.material) return a.material < b.material;
    if (a.volume != b.volume) return a.volume < b.volume;
    if (a.mass != b.mass) return a.mass < b.mass;
    for (int d = 0; d < Dim; ++d) {
      if (a.moment[d] != b.moment[d]) return a.moment[d] < b.moment[d];
    }
    return a.covers < b.covers;
  });

  const double cell_volume = std::pow(options.dx, Dim);
  std::vector<Vec<Dim>> x;
  std::vector<double> density;
  std::vector<int> material;
  for (std::size_t k = 0; k < deposits.size();) {
    const std::int64_t cell = deposits[k].cell;
    double volume = 0.0, mass = 0.0, best_volume = -1.0;
    Vec<Dim> moment = Vec<Dim>::Zero();
    int best_material = -1;
    bool covered = false;
    while (k < deposits.size() && deposits[k].cell == cell) {
      const int m = deposits[k].material;
      double volume_m = 0.0;
      for (; k < deposits.size() && deposits[k].cell == cell && deposits[k].material == m; ++k) {
        volume_m += deposits[k].volume;
        mass += deposits[k].mass;
        moment += deposits[k].moment;
        covered = covered || deposits[k].covers;
      }
      volume += volume_m;
      if (volume_m > best_volume) {  // ties go to the lower material index
        best_volume = volume_m;
        best_material = m;
      }
    }
    // The cell's fill (its deposited volume over its own) decides whether it holds a stress point.
    const bool filled = volume >= options.fill * cell_volume;
    if (!filled && !(covered && volume > 0.0)) continue;
    const auto c = unpack<Dim>(cell);
    Vec<Dim> centre;
    for (int d = 0; d < Dim; ++d) {
      centre[d] = origin[d] + (static_cast<double>(c[static_cast<std::size_t>(d)]) + 0.5) * options.dx;
    }
    // A cell held by the cover window alone gets its stress point at the centroid of its
    // deposits (inside the node cloud), not at its centre, which may lie beyond the surface.
    if (!filled) centre = moment / volume;
    if (options.excluded && options.excluded(centre.data())) {
      ++result.excluded_cells;
      continue;
    }
    const int from_old = nearest_old_material(c, centre);
    x.push_back(centre);
    density.push_back(mass / volume);  // eq. (5.2.2)
    material.push_back(from_old >= 0 ? from_old : best_material);
  }
  if (x.empty()) throw SolverError("re-seeding: no lattice cell is filled by the nodes");

  // Eq. (5.2.3): one cell's volume each, scaled by one factor that keeps the set's mass.
  double mass_new = 0.0;
  for (const double rho : density) mass_new += rho * cell_volume;
  result.volume_factor = mass_before > 0.0 ? mass_before / mass_new : 1.0;
  std::vector<double> volume(x.size(), result.volume_factor * cell_volume);
  std::vector<std::int64_t> ids(x.size());
  for (auto& id : ids) id = next_global_id++;
  result.after = static_cast<Index>(x.size());
  stress_points.replace(std::move(x), std::move(volume), std::move(density), std::move(material), std::move(ids));
  return result;
}

template ReseedResult reseed_stress_points<1>(const ParticleSet<1>&, const Vec<1>&, const ReseedOptions&,
                                              ParticleSet<1>&, std::int64_t&);
template ReseedResult reseed_stress_points<2>(const ParticleSet<2>&, const Vec<2>&, const ReseedOptions&,
                                              ParticleSet<2>&, std::int64_t&);
template ReseedResult reseed_stress_points<3>(const ParticleSet<3>&, const Vec<3>&, const ReseedOptions&,
                                              ParticleSet<3>&, std::int64_t&);

}  // namespace rktsph
