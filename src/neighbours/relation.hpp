#pragma once
// A neighbour relation between two particle sets (docs/architecture.md, "Relations"): for every
// target point, the source particles within a radius, stored as CSR (offsets + source indices).
//
// The relation is rebuilt on request, e.g. after the particles have moved; every build bumps
// version(), so that operators computed from it can tell they are stale. It is built with the
// cell list (neighbours/cell_list.hpp) in fixed blocks of targets, so the result does not
// depend on the number of threads.
#include <cstdint>
#include <span>
#include <vector>

#include "core/execution.hpp"
#include "core/types.hpp"
#include "neighbours/cell_list.hpp"

namespace rktsph {

struct RelationOptions {
  double radius = 0.0;  // sources with |x_target - x_source| < radius are neighbours
  /// Cells of side radius / subdivisions (cell_list.hpp). It fixes the order of a row when the
  /// row is not sorted.
  int subdivisions = 2;
  /// true: each row sorted by source index. false: in the order the cell list visits them
  /// (cells x fastest, each cell's particles by index).
  bool sorted = true;
};

template <int Dim>
class Relation {
 public:
  /// (Re)build from the current positions.
  void build(const std::vector<Vec<Dim>>& targets, const std::vector<Vec<Dim>>& sources, const RelationOptions& options,
             const exec::Threads& policy = {});

  /// The transpose of `other` (built from targets T to sources S, with `rows` = |S|): for every
  /// source of `other`, the targets whose rows hold it, sorted. The distance test is symmetric
  /// (|x_t - x_s|^2 and |x_s - x_t|^2 are the same bits), so this is the relation a search from
  /// S to T at other's radius finds, at the cost of a counting sort instead of a cell-list search.
  void build_transpose(const Relation& other, Index rows);

  Index rows() const { return static_cast<Index>(offsets_.size()) - 1; }
  std::size_t pairs() const { return indices_.size(); }
  /// Sources of target a, in row order.
  std::span<const Index> row(Index a) const {
    const auto b = static_cast<std::size_t>(offsets_[static_cast<std::size_t>(a)]);
    const auto e = static_cast<std::size_t>(offsets_[static_cast<std::size_t>(a) + 1]);
    return {indices_.data() + b, e - b};
  }
  const std::vector<Index>& offsets() const { return offsets_; }
  const std::vector<Index>& indices() const { return indices_; }
  const RelationOptions& options() const { return options_; }
  /// Incremented by every build (0: never built).
  std::uint64_t version() const { return version_; }
  std::size_t bytes() const { return (offsets_.size() + indices_.size()) * sizeof(Index); }
  /// Drop the pairs (fixed particles: once the operators are computed, the relation is not
  /// needed until the next rebuild). The version is kept.
  void release() {
    offsets_ = {0};
    indices_ = {};
  }

 private:
  std::vector<Index> offsets_{0};
  std::vector<Index> indices_;
  RelationOptions options_;
  std::uint64_t version_ = 0;
};

}  // namespace rktsph
