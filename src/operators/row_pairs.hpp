#pragma once
// The pairs of one row of a relation, with their separation: shared by the operator builders
// (corrected_operator.cpp, difference_gradient.cpp). Internal to src/operators.
#include <cmath>
#include <vector>

#include "core/types.hpp"
#include "neighbours/relation.hpp"
#include "particles/particle_set.hpp"

namespace rktsph::detail {

template <int Dim>
struct Pair {
  Index b;
  Vec<Dim> x_ab;  // x_a - x_b
  double r;
};

// The pairs of row a of a relation (sources in row order), with x_a - x_b and the distance.
template <int Dim>
void row_pairs(const Relation<Dim>& relation, Index a, const Vec<Dim>& xa, const ParticleSet<Dim>& sources,
               std::vector<Pair<Dim>>& pairs) {
  const auto row = relation.row(a);
  pairs.resize(row.size());
  for (std::size_t k = 0; k < row.size(); ++k) {
    const Vec<Dim> x_ab = xa - sources.position[static_cast<std::size_t>(row[k])];
    pairs[k] = {row[k], x_ab, std::sqrt(x_ab.squaredNorm())};
  }
}

}  // namespace rktsph::detail
