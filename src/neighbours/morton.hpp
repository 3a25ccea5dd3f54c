#pragma once
// Particles stored in Morton (Z-curve) order of the cells they lie in (method-notes §3.8,
// "Storage order"): neighbours in space are then mostly neighbours in memory, so that the pair
// loops of a moving-particle step read their sources from a few cache lines instead of from
// all over the arrays. Cells are squares (cubes) of a given side over a given origin; within a
// cell the particles keep the order of their global ids, so the order is a function of the
// positions and ids alone: the same on any thread count and whatever order the set was in.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

namespace morton_detail {
/// Spread the low bits of v so that bit b lands on bit Dim*b.
template <int Dim>
constexpr std::uint64_t spread(std::uint64_t v) {
  if constexpr (Dim == 1) {
    return v;
  } else if constexpr (Dim == 2) {  // 32 bits -> every other bit
    v &= 0xffffffffULL;
    v = (v | (v << 16)) & 0x0000ffff0000ffffULL;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffULL;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0fULL;
    v = (v | (v << 2)) & 0x3333333333333333ULL;
    v = (v | (v << 1)) & 0x5555555555555555ULL;
    return v;
  } else {  // 21 bits -> every third bit
    v &= 0x1fffffULL;
    v = (v | (v << 32)) & 0x1f00000000ffffULL;
    v = (v | (v << 16)) & 0x1f0000ff0000ffULL;
    v = (v | (v << 8)) & 0x100f00f00f00f00fULL;
    v = (v | (v << 4)) & 0x10c30c30c30c30c3ULL;
    v = (v | (v << 2)) & 0x1249249249249249ULL;
    return v;
  }
}
}  // namespace morton_detail

/// The Morton key of cell c (coordinates clamped to the key's range: 62 bits in 1D, 32 per axis
/// in 2D, 21 in 3D; a cell beyond it shares the last key with its neighbours, still in order).
template <int Dim>
std::uint64_t morton_key(const std::array<std::int64_t, Dim>& c) {
  constexpr int bits = Dim == 1 ? 62 : (Dim == 2 ? 32 : 21);
  constexpr std::int64_t top = (std::int64_t{1} << bits) - 1;
  std::uint64_t key = 0;
  for (int d = 0; d < Dim; ++d) {
    const auto v = static_cast<std::uint64_t>(std::clamp<std::int64_t>(c[static_cast<std::size_t>(d)], 0, top));
    key |= morton_detail::spread<Dim>(v) << d;
  }
  return key;
}

/// The order that sorts `x` by the Morton key of its cell (side `cell`, origin `lo`, below every
/// point), ties by `id`: order[k] is the particle that goes to place k. Returns false, with
/// `order` left as the identity, when the particles are in that order already. `keys` is work
/// space (kept by the caller: no allocation after the first call).
template <int Dim>
bool morton_order(const std::vector<Vec<Dim>>& x, const std::vector<std::int64_t>& id, const Vec<Dim>& lo, double cell,
                  std::vector<Index>& order, std::vector<std::uint64_t>& keys) {
  const std::size_t n = x.size();
  keys.resize(n);
  order.resize(n);
  const double inv = 1.0 / cell;
  for (std::size_t i = 0; i < n; ++i) {
    std::array<std::int64_t, Dim> c{};
    for (int d = 0; d < Dim; ++d) {
      c[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::floor((x[i][d] - lo[d]) * inv));
    }
    keys[i] = morton_key<Dim>(c);
    order[i] = static_cast<Index>(i);
  }
  auto before = [&](Index a, Index b) {
    const auto au = static_cast<std::size_t>(a), bu = static_cast<std::size_t>(b);
    return keys[au] != keys[bu] ? keys[au] < keys[bu] : id[au] < id[bu];
  };
  if (std::is_sorted(order.begin(), order.end(), before)) return false;
  std::sort(order.begin(), order.end(), before);
  return true;
}

}  // namespace rktsph
