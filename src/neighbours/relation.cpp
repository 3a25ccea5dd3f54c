#include "neighbours/relation.hpp"

#include <algorithm>

namespace rktsph {

namespace {
// Targets per block: each block collects its rows on its own, then the blocks are joined in order.
constexpr Index kRelationBlock = 1024;
}  // namespace

template <int Dim>
void Relation<Dim>::build(const std::vector<Vec<Dim>>& targets, const std::vector<Vec<Dim>>& sources,
                          const RelationOptions& options, const exec::Threads& policy) {
  options_ = options;
  const CellList<Dim> cells(sources, options.radius, options.subdivisions);
  const auto nt = static_cast<Index>(targets.size());
  const Index nblocks = (nt + kRelationBlock - 1) / kRelationBlock;
  // The blocks' rows, kept from build to build by the calling thread (a V2 run searches again
  // every few steps; fresh vectors each time cost their growth copies and page faults), shared
  // by every relation that thread builds, so they hold one relation's pairs at most.
  // (References, so that the team's threads use the caller's vectors, not their own.)
  static thread_local std::vector<std::vector<Index>> pool;
  static thread_local std::vector<Index> pool_counts;
  std::vector<std::vector<Index>>& block_indices = pool;
  std::vector<Index>& counts = pool_counts;
  if (block_indices.size() < static_cast<std::size_t>(nblocks)) block_indices.resize(static_cast<std::size_t>(nblocks));
  counts.resize(static_cast<std::size_t>(nt));
  const double r2 = options.radius * options.radius;
  exec::particle_for(
      policy, nblocks,
      [&](Index blk) {
        static thread_local std::vector<typename CellList<Dim>::Hit> hits;
        static thread_local std::vector<Index> row;
        auto& out = block_indices[static_cast<std::size_t>(blk)];
        out.clear();
        const Index end = std::min(nt, (blk + 1) * kRelationBlock);
        for (Index a = blk * kRelationBlock; a < end; ++a) {
          const std::size_t n = cells.collect(targets[static_cast<std::size_t>(a)], r2, hits);
          row.resize(n);
          for (std::size_t k = 0; k < n; ++k) row[k] = hits[k].j;
          if (options.sorted) std::sort(row.begin(), row.end());
          out.insert(out.end(), row.begin(), row.end());
          counts[static_cast<std::size_t>(a)] = static_cast<Index>(n);
        }
      },
      exec::Schedule::dynamic, nt);
  offsets_.assign(static_cast<std::size_t>(nt) + 1, 0);
  for (Index a = 0; a < nt; ++a)
    offsets_[static_cast<std::size_t>(a) + 1] =
        offsets_[static_cast<std::size_t>(a)] + counts[static_cast<std::size_t>(a)];
  indices_.clear();
  indices_.reserve(static_cast<std::size_t>(offsets_.back()));
  for (Index blk = 0; blk < nblocks; ++blk) {
    const auto& b = block_indices[static_cast<std::size_t>(blk)];
    indices_.insert(indices_.end(), b.begin(), b.end());
  }
  ++version_;
}

template <int Dim>
void Relation<Dim>::build_transpose(const Relation& other, Index rows) {
  options_ = other.options_;
  options_.sorted = true;  // targets appended in increasing order
  const auto n = static_cast<std::size_t>(rows);
  offsets_.assign(n + 1, 0);
  for (const Index j : other.indices_) ++offsets_[static_cast<std::size_t>(j) + 1];
  for (std::size_t j = 0; j < n; ++j) offsets_[j + 1] += offsets_[j];
  indices_.resize(other.indices_.size());
  static thread_local std::vector<Index> cursor;
  cursor.assign(offsets_.begin(), offsets_.end() - 1);
  for (Index a = 0; a < other.rows(); ++a) {
    for (const Index j : other.row(a)) indices_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(j)]++)] = a;
  }
  ++version_;
}

template class Relation<1>;
template class Relation<2>;
template class Relation<3>;

}  // namespace rktsph
