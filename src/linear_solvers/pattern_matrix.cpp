#include "linear_solvers/pattern_matrix.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/execution.hpp"

namespace rktsph {

namespace {
// Candidates compared per signature before a row gets a new pattern: on a lattice the class a
// row belongs to is among the last few seen with its offsets; on a jittered set every row is new
// and the bound keeps the build linear.
constexpr std::size_t kCandidates = 16;
// Rows per task of the product: large enough that a task outweighs its scheduling.
constexpr Index kRowBlock = 512;
// From this many rows on, the product runs on the threads (a few thousand rows cost less than a
// fork/join).
constexpr Index kParallelRows = 16384;
// Rows summed together in a run (vector registers' worth of accumulators).
constexpr Index kRun = 16;

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h;
}
}  // namespace

PatternMatrix::Builder::Builder(Index rows, Index cols, double relative_tolerance)
    : storage_(1), tolerance_(relative_tolerance) {
  m_ = &storage_.front();
  m_->cols_ = cols;
  m_->base_.reserve(static_cast<std::size_t>(rows));
  m_->pattern_.reserve(static_cast<std::size_t>(rows));
}

Index PatternMatrix::Builder::find_or_add(std::span<const Index> columns, std::span<const double> values,
                                          std::uint64_t signature) {
  const Index base = columns.empty() ? 0 : columns.front();
  double scale = 0.0;
  for (double v : values) scale = std::max(scale, std::abs(v));
  const double tol = tolerance_ * scale;
  auto& candidates = by_signature_[signature];
  for (auto it = candidates.rbegin(); it != candidates.rend(); ++it) {
    const auto p = static_cast<std::size_t>(*it);
    const auto b = static_cast<std::size_t>(m_->pattern_start_[p]);
    const auto e = static_cast<std::size_t>(m_->pattern_start_[p + 1]);
    if (e - b != columns.size()) continue;
    bool same = true;
    for (std::size_t k = 0; k < columns.size() && same; ++k) {
      same = m_->offset_[b + k] == columns[k] - base && std::abs(m_->value_[b + k] - values[k]) <= tol;
    }
    if (same) return *it;
  }
  const Index p = m_->patterns();
  for (std::size_t k = 0; k < columns.size(); ++k) {
    m_->offset_.push_back(columns[k] - base);
    m_->value_.push_back(values[k]);
  }
  m_->pattern_start_.push_back(static_cast<Index>(m_->offset_.size()));
  candidates.push_back(p);
  if (candidates.size() > kCandidates) candidates.erase(candidates.begin());
  return p;
}

void PatternMatrix::Builder::add_row(std::span<const Index> columns, std::span<const double> values) {
  if (columns.size() != values.size()) throw SolverError("pattern matrix: a row's columns and values differ in length");
  const Index base = columns.empty() ? 0 : columns.front();
  std::uint64_t signature = columns.size();
  for (std::size_t k = 0; k < columns.size(); ++k) {
    if (columns[k] < 0 || columns[k] >= m_->cols_ || (k > 0 && columns[k] <= columns[k - 1])) {
      throw SolverError("pattern matrix: a row's columns are not increasing inside the matrix");
    }
    signature = mix(signature, static_cast<std::uint64_t>(columns[k] - base));
  }
  m_->pattern_.push_back(find_or_add(columns, values, signature));
  m_->base_.push_back(base);
  m_->nonzeros_ += columns.size();
}

PatternMatrix PatternMatrix::Builder::finish() {
  by_signature_.clear();
  PatternMatrix out = std::move(storage_.front());
  out.offset_.shrink_to_fit();
  out.value_.shrink_to_fit();
  out.pattern_start_.shrink_to_fit();
  return out;
}

PatternMatrix::PatternMatrix(const Sparse& a, double relative_tolerance) {
  Builder builder(static_cast<Index>(a.rows()), static_cast<Index>(a.cols()), relative_tolerance);
  std::vector<Index> columns;
  std::vector<double> values;
  for (Eigen::Index r = 0; r < a.outerSize(); ++r) {
    columns.clear();
    values.clear();
    for (Sparse::InnerIterator it(a, r); it; ++it) {
      columns.push_back(static_cast<Index>(it.col()));
      values.push_back(it.value());
    }
    builder.add_row(columns, values);
  }
  *this = builder.finish();
}

std::size_t PatternMatrix::bytes() const {
  return (base_.size() + pattern_.size() + pattern_start_.size() + offset_.size()) * sizeof(Index) +
         value_.size() * sizeof(double);
}

template <bool Add>
void PatternMatrix::product(const double* x, double* y, double alpha) const {
  const Index n = rows();
  const Index blocks = (n + kRowBlock - 1) / kRowBlock;
  const Index* base = base_.data();
  const Index* pattern = pattern_.data();
  const Index* start = pattern_start_.data();
  const Index* offset = offset_.data();
  const double* value = value_.data();
  exec::particle_for(
      exec::Threads{kParallelRows}, blocks,
      [&](Index blk) {
        const Index end = std::min(n, (blk + 1) * kRowBlock);
        for (Index r = blk * kRowBlock; r < end;) {
          // A run: rows with one pattern and consecutive bases (a lattice line). For each entry
          // k their sources are contiguous, so the run's sums are vector operations; each row
          // still sums its entries in pattern order, as a row alone would.
          const Index p = pattern[r];
          Index len = 1;
          while (len < kRun && r + len < end && pattern[r + len] == p && base[r + len] == base[r] + len) ++len;
          double sum[kRun] = {};
          const double* xb = x + base[r];
          if (len == kRun) {  // the common case, at a length the compiler unrolls into vectors
            for (Index k = start[p]; k < start[p + 1]; ++k) {
              const double v = value[k];
              const double* xk = xb + offset[k];
              for (Index l = 0; l < kRun; ++l) sum[l] += v * xk[l];
            }
          } else {
            for (Index k = start[p]; k < start[p + 1]; ++k) {
              const double v = value[k];
              const double* xk = xb + offset[k];
              for (Index l = 0; l < len; ++l) sum[l] += v * xk[l];
            }
          }
          for (Index l = 0; l < len; ++l) {
            if constexpr (Add) {
              y[r + l] += alpha * sum[l];
            } else {
              y[r + l] = sum[l];
            }
          }
          r += len;
        }
      },
      exec::Schedule::even, n);
}

void PatternMatrix::multiply(std::span<const double> x, std::span<double> y) const {
  product<false>(x.data(), y.data(), 1.0);
}

void PatternMatrix::multiply_add(std::span<const double> x, std::span<double> y, double alpha) const {
  product<true>(x.data(), y.data(), alpha);
}

Eigen::VectorXd PatternMatrix::diagonal() const {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(rows());
  for (Index r = 0; r < rows(); ++r) {
    const auto p = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(r)]);
    for (Index k = pattern_start_[p]; k < pattern_start_[p + 1]; ++k) {
      if (base_[static_cast<std::size_t>(r)] + offset_[static_cast<std::size_t>(k)] == r) {
        d[r] = value_[static_cast<std::size_t>(k)];
      }
    }
  }
  return d;
}

PatternMatrix::Sparse PatternMatrix::to_sparse() const {
  Sparse a(rows(), cols());
  Eigen::VectorXi per_row(rows());
  for (Index r = 0; r < rows(); ++r) {
    const auto p = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(r)]);
    per_row[r] = pattern_start_[p + 1] - pattern_start_[p];
  }
  a.reserve(per_row);
  for (Index r = 0; r < rows(); ++r) {
    const auto p = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(r)]);
    for (Index k = pattern_start_[p]; k < pattern_start_[p + 1]; ++k) {
      a.insert(r, base_[static_cast<std::size_t>(r)] + offset_[static_cast<std::size_t>(k)]) =
          value_[static_cast<std::size_t>(k)];
    }
  }
  a.makeCompressed();
  return a;
}

}  // namespace rktsph
