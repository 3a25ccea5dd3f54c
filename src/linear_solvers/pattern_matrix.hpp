#pragma once
// A sparse matrix stored by shared row patterns, the layout of the corrected operators
// (operators/corrected_operator.hpp) applied to the pore-pressure system (method-notes §5.3).
//
// On a lattice the rows of the pressure matrix K and of the right-hand-side operator are shifted
// copies of a few classes: the interior rows are one class, the rows near each face, edge and
// corner a few more. So each row is stored as (base column, pattern id), and a pattern holds its
// column offsets from the base and its values. A product streams x and y and reads the weights of
// a handful of patterns from the L1 cache: 8 bytes per row instead of 12 per nonzero, and no
// longer bound by the matrix's memory traffic. Rows whose values differ (a jittered set, rows
// cut by a drained face) get their own patterns: nothing is lost in generality.
//
// Rows are matched with a relative tolerance on their values (the weights of two rows of the
// same geometry agree to round-off, not bit for bit, since each is computed from its own
// positions); the first row of a class supplies the values for all of them.
//
// The product computes each row's sum serially in pattern order, whichever thread runs it, so
// its result does not depend on the thread count.
#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/SparseCore>

#include "core/types.hpp"

namespace rktsph {

class PatternMatrix {
 public:
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  /// Rows are added in order with add_row(); finish() releases the look-up tables.
  class Builder {
   public:
    Builder(Index rows, Index cols, double relative_tolerance = kDefaultTolerance);
    Builder(const Builder&) = delete;
    Builder& operator=(const Builder&) = delete;
    /// The next row: columns strictly increasing, values beside them (zeros allowed).
    void add_row(std::span<const Index> columns, std::span<const double> values);
    PatternMatrix finish();

   private:
    Index find_or_add(std::span<const Index> columns, std::span<const double> values, std::uint64_t signature);
    std::vector<PatternMatrix> storage_;  // the one matrix being built (PatternMatrix is incomplete here)
    PatternMatrix* m_ = nullptr;
    double tolerance_;
    std::unordered_map<std::uint64_t, std::vector<Index>> by_signature_;
  };

  static constexpr double kDefaultTolerance = 1e-12;

  PatternMatrix() = default;
  /// The same matrix from an Eigen row-major sparse matrix.
  explicit PatternMatrix(const Sparse& a, double relative_tolerance = kDefaultTolerance);

  Index rows() const { return static_cast<Index>(base_.size()); }
  Index cols() const { return cols_; }
  Index patterns() const { return static_cast<Index>(pattern_start_.size()) - 1; }
  /// Stored entries summed over all rows (the CSR length).
  std::size_t nonzeros() const { return nonzeros_; }
  std::size_t bytes() const;

  /// Row r: its entries are (base + offset[k], value[k]), columns increasing.
  struct RowView {
    Index base;
    std::span<const Index> offset;
    std::span<const double> value;
  };
  RowView row(Index r) const {
    const auto p = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(r)]);
    const auto b = static_cast<std::size_t>(pattern_start_[p]);
    const auto e = static_cast<std::size_t>(pattern_start_[p + 1]);
    return {base_[static_cast<std::size_t>(r)], {offset_.data() + b, e - b}, {value_.data() + b, e - b}};
  }

  /// y = A x.
  void multiply(std::span<const double> x, std::span<double> y) const;
  /// y += alpha A x.
  void multiply_add(std::span<const double> x, std::span<double> y, double alpha) const;
  /// The diagonal (rows() entries; 0 where a row has none).
  Eigen::VectorXd diagonal() const;
  /// The full matrix (tests, and the incomplete-Cholesky option, which needs the entries).
  Sparse to_sparse() const;

 private:
  friend class Builder;
  template <bool Add>
  void product(const double* x, double* y, double alpha) const;
  std::vector<Index> base_;     // per row: the column of its pattern's offset 0
  std::vector<Index> pattern_;  // per row: its pattern
  std::vector<Index> pattern_start_{0};
  std::vector<Index> offset_;   // per pattern entry: column - base
  std::vector<double> value_;   // per pattern entry
  Index cols_ = 0;
  std::size_t nonzeros_ = 0;
};

}  // namespace rktsph
