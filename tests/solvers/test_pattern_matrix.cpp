// The shared-row-pattern sparse matrix of the pressure solve (linear_solvers/pattern_matrix.hpp):
// the product equals the CSR product, lattice rows share a few patterns, rows that differ by
// more than the tolerance do not, and the product is the same bit for bit on 1 and 2 threads.
#include <gtest/gtest.h>

#include <omp.h>

#include <random>
#include <vector>

#include "../support/node_lattice.hpp"
#include "core/error.hpp"
#include "core/kernel.hpp"
#include "linear_solvers/pattern_matrix.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/laplacian.hpp"

namespace rktsph {
namespace {

using Sparse = PatternMatrix::Sparse;

ParticleSet<2> lattice(int n, int m, double dx) { return test::node_lattice(n, m, dx); }

std::vector<double> random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> v(static_cast<std::size_t>(n));
  for (double& x : v) x = u(gen);
  return v;
}

double max_difference(const Sparse& a, const PatternMatrix& p, const std::vector<double>& x) {
  const Eigen::VectorXd ref = a * Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
  std::vector<double> y(static_cast<std::size_t>(a.rows()), 7.0);
  p.multiply(x, y);
  double err = 0.0;
  for (Eigen::Index r = 0; r < a.rows(); ++r) err = std::max(err, std::abs(y[static_cast<std::size_t>(r)] - ref[r]));
  return err / std::max(1.0, ref.cwiseAbs().maxCoeff());
}

TEST(PatternMatrix, LatticeLaplacianRowsSharePatternsAndTheProductMatchesCsr) {
  const auto s = lattice(60, 40, 0.1);
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.12));
  const PatternMatrix p(lap.full);
  EXPECT_EQ(p.rows(), lap.full.rows());
  EXPECT_EQ(p.nonzeros(), static_cast<std::size_t>(lap.full.nonZeros()));
  // Interior, faces, edges and corners: a few dozen classes for 2501 rows.
  EXPECT_LT(p.patterns(), 100);
  EXPECT_LT(p.bytes(), static_cast<std::size_t>(lap.full.nonZeros()) * 12 / 5);
  EXPECT_LT(max_difference(lap.full, p, random_vector(lap.full.cols(), 1)), 1e-11);
  // The round trip keeps every entry to the sharing tolerance.
  const Sparse back = p.to_sparse();
  EXPECT_LT((Sparse(back - lap.full)).coeffs().cwiseAbs().maxCoeff(), 1e-12 * lap.full.coeffs().cwiseAbs().maxCoeff());
  const Eigen::VectorXd d = p.diagonal();
  for (Eigen::Index r = 0; r < lap.full.rows(); ++r) EXPECT_EQ(d[r], back.coeff(r, r));
}

TEST(PatternMatrix, RowsThatDifferBeyondTheToleranceKeepTheirOwnValues) {
  // A tridiagonal matrix whose rows are shifted copies except one, perturbed by 1e-9.
  const int n = 50;
  Sparse a(n, n);
  std::vector<Eigen::Triplet<double>> t;
  for (int r = 0; r < n; ++r) {
    const double bump = r == 20 ? 1e-9 : 0.0;
    if (r > 0) t.emplace_back(r, r - 1, -1.0);
    t.emplace_back(r, r, 2.0 + bump);
    if (r + 1 < n) t.emplace_back(r, r + 1, -1.0);
  }
  a.setFromTriplets(t.begin(), t.end());
  const PatternMatrix p(a);
  EXPECT_EQ(p.patterns(), 4);  // first row, interior, the perturbed row, last row
  EXPECT_EQ(p.diagonal()[20], 2.0 + 1e-9);
  EXPECT_EQ(max_difference(a, p, random_vector(n, 2)), 0.0);
  // multiply_add: y += alpha A x.
  const auto x = random_vector(n, 3);
  std::vector<double> y(n, 1.0);
  p.multiply_add(x, y, -2.0);
  const Eigen::VectorXd ref =
      Eigen::VectorXd::Ones(n) - 2.0 * (a * Eigen::Map<const Eigen::VectorXd>(x.data(), n));
  for (int r = 0; r < n; ++r) EXPECT_NEAR(y[static_cast<std::size_t>(r)], ref[r], 1e-15);
}

TEST(PatternMatrix, JitteredRowsGetTheirOwnPatternsAndStayExact) {
  auto s = lattice(30, 30, 0.1);
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (auto& x : s.position) x += Vec<2>(u(gen), u(gen));
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.12));
  const PatternMatrix p(lap.symmetric);
  EXPECT_GT(p.patterns(), lap.symmetric.rows() / 2);
  EXPECT_LT(max_difference(lap.symmetric, p, random_vector(lap.symmetric.cols(), 4)), 1e-14);
}

TEST(PatternMatrix, ProductIsTheSameOnOneAndTwoThreads) {
  const auto s = lattice(200, 120, 0.05);  // 24321 rows: above the parallel threshold
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.06));
  const PatternMatrix p(lap.full);
  const auto x = random_vector(lap.full.cols(), 6);
  std::vector<double> y1(static_cast<std::size_t>(p.rows())), y2(y1.size());
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  p.multiply(x, y1);
  omp_set_num_threads(2);
  p.multiply(x, y2);
  omp_set_num_threads(threads);
  EXPECT_EQ(y1, y2);
}

TEST(PatternMatrix, BadRowsAreRefused) {
  PatternMatrix::Builder b(2, 3);
  const std::vector<Index> unsorted{2, 1};
  const std::vector<double> v{1.0, 2.0};
  EXPECT_THROW(b.add_row(unsorted, v), SolverError);
  const std::vector<Index> outside{0, 3};
  EXPECT_THROW(b.add_row(outside, v), SolverError);
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// The pressure stage builds L, S and the filter's T G row by row into pattern storage; they
// must equal the CSR builds the operator tests check (to the sharing tolerance), with mirror
// walls and on a jittered set.
TEST(PatternMatrix, RowByRowPressureOperatorsEqualTheCsrBuilds) {
  for (double jitter : {0.0, 0.02}) {
    auto s = lattice(24, 18, 0.1);
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(-jitter, jitter);
    for (auto& x : s.position) x += Vec<2>(u(gen), u(gen));
    const CubicSplineKernel<2> kernel(0.12);
    const std::vector<MirrorPlane> walls = {{0, 0.0, -1}, {1, 0.0, -1}};
    Relation<2> relation;
    relation.build(s.position, s.position, laplacian_relation_options(kernel), exec::Threads{});
    const auto csr = build_node_laplacian<2>(relation, s, kernel, {}, walls, {});
    const auto pat = build_node_laplacian_patterns<2>(relation, s, kernel, walls, {});
    const double scale = csr.full.coeffs().cwiseAbs().maxCoeff();
    EXPECT_LT(Sparse(pat.full.to_sparse() - csr.full).coeffs().cwiseAbs().maxCoeff(), 1e-11 * scale) << jitter;
    EXPECT_LT(Sparse(pat.symmetric.to_sparse() - csr.symmetric).coeffs().cwiseAbs().maxCoeff(), 1e-11 * scale)
        << jitter;
    EXPECT_EQ(pat.degenerate_rows, csr.degenerate_rows);
    const auto op = build_corrected_operator<2>(s.position, s, kernel);
    const Sparse tg_csr = build_filter_gradient_part<2>(csr.symmetric, s.position, gradient_matrices<2>(op, s.size()));
    const PatternMatrix tg = build_filter_gradient_patterns<2>(pat.symmetric, s.position, op);
    const double tg_scale = tg_csr.coeffs().cwiseAbs().maxCoeff();
    EXPECT_LT(Sparse(tg.to_sparse() - tg_csr).coeffs().cwiseAbs().maxCoeff(), 1e-10 * tg_scale) << jitter;
  }
}

}  // namespace
}  // namespace rktsph
