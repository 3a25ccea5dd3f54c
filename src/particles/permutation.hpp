#pragma once
// Reordering particles (docs/architecture.md, "Particle state"): an order is a permutation of
// [0, n) with "particle k of the result is particle order[k] before", and every array with one
// row per particle moves its rows with it, in place (its storage, and so every view and
// pointer into it, stays valid).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

/// A reordering of a scheme's particle sets; an empty order leaves its set as it is.
struct Reordering {
  std::vector<Index> nodes;
  std::vector<Index> stress_points;
  bool empty() const { return nodes.empty() && stress_points.empty(); }
};

/// A random reordering of both sets (what a long mixing flow leaves in memory), the same for a
/// given seed: for tests and benchmarks of the storage order.
inline Reordering shuffled_orders(Index nodes, Index stress_points, std::uint32_t seed) {
  Reordering r;
  for (auto* order : {&r.nodes, &r.stress_points}) {
    order->resize(static_cast<std::size_t>(order == &r.nodes ? nodes : stress_points));
    std::iota(order->begin(), order->end(), Index{0});
    std::shuffle(order->begin(), order->end(), std::mt19937(seed));
  }
  return r;
}

/// new_index[old] = new: where each particle went.
inline std::vector<Index> inverse_order(const std::vector<Index>& order) {
  std::vector<Index> new_index(order.size(), Index{0});
  for (std::size_t k = 0; k < order.size(); ++k) new_index[static_cast<std::size_t>(order[k])] = static_cast<Index>(k);
  return new_index;
}

/// Rows of `stride` values: row k becomes row order[k], in place (through one copy). An empty
/// array (an unused field) stays empty.
template <class T>
void permute_rows(std::vector<T>& values, const std::vector<Index>& order, std::size_t stride = 1) {
  if (values.empty()) return;
  const std::vector<T> before(values);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const auto from = static_cast<std::ptrdiff_t>(static_cast<std::size_t>(order[k]) * stride);
    std::copy_n(before.begin() + from, stride, values.begin() + static_cast<std::ptrdiff_t>(k * stride));
  }
}

/// Index lists that name particles: each entry i becomes new_index[i].
inline void renumber(std::vector<Index>& indices, const std::vector<Index>& new_index) {
  for (Index& i : indices) i = new_index[static_cast<std::size_t>(i)];
}

}  // namespace rktsph
