// Schwaiger-corrected node Laplacian (method-notes §3.5, §6 item 7): exact for linear fields on
// irregular and truncated particle sets (edges and corners included), within 1 % for a
// quadratic field in the interior, symmetric part symmetric with zero row sums, and the
// impermeable-wall rows reproduce the even extension of a field with zero normal derivative.
// The linear-exact pressure filter S - T G vanishes for linear fields everywhere and for
// quadratic fields inside, and acts fully on the odd-even (checkerboard) mode.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "core/kernel.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/laplacian.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

// n x m lattice of spacing dx with tributary volumes, optionally jittered by +-jitter*dx.
ParticleSet<2> lattice2(int n, int m, double dx, double jitter, unsigned seed = 7) {
  ParticleSet<2> s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter * dx, jitter * dx);
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i <= n; ++i) {
      Vec<2> x(i * dx, j * dx);
      if (jitter > 0.0) x += Vec<2>(u(rng), u(rng));
      s.position.push_back(x);
      const double fx = (i == 0 || i == n) ? 0.5 : 1.0, fy = (j == 0 || j == m) ? 0.5 : 1.0;
      s.volume.push_back(fx * fy * dx * dx);
      s.density.push_back(1.0);
      s.material.push_back(0);
    }
  }
  return s;
}

Eigen::VectorXd sample(const ParticleSet<2>& s, double (*f)(const Vec<2>&)) {
  Eigen::VectorXd v(s.size());
  for (Index i = 0; i < s.size(); ++i) v[i] = f(s.position[static_cast<std::size_t>(i)]);
  return v;
}

double linear(const Vec<2>& x) { return 3.0 - 2.0 * x[0] + 5.0 * x[1]; }
double quadratic(const Vec<2>& x) { return x[0] * x[0] + x[1] * x[1]; }

TEST(Laplacian, ExactForLinearFieldsOnJitteredAndTruncatedSets) {
  for (double jitter : {0.0, 0.2}) {
    const double dx = 0.1;
    const auto s = lattice2(10, 10, dx, jitter);
    const CubicSplineKernel<2> kernel(1.2 * dx);
    const auto lap = build_node_laplacian<2>(s, kernel);
    EXPECT_EQ(lap.degenerate_rows, 0);
    const Eigen::VectorXd f = sample(s, linear);
    const Eigen::VectorXd Lf = lap.full * f;
    // Scale: |L_II| |f| ~ (1/dx^2) * 5 (every node, edges and corners included).
    EXPECT_LT(Lf.cwiseAbs().maxCoeff(), 1e-9 * 5.0 / (dx * dx)) << "jitter " << jitter;
  }
}

TEST(Laplacian, ExactForLinearFieldsIn1D) {
  ParticleSet<1> s;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (int i = 0; i <= 20; ++i) {
    Vec<1> x;
    x[0] = 0.1 * i + (i > 0 && i < 20 ? u(rng) : 0.0);
    s.position.push_back(x);
    s.volume.push_back(i == 0 || i == 20 ? 0.05 : 0.1);
    s.density.push_back(1.0);
    s.material.push_back(0);
  }
  const auto lap = build_node_laplacian<1>(s, CubicSplineKernel<1>(0.12));
  Eigen::VectorXd f(s.size());
  for (Index i = 0; i < s.size(); ++i) f[i] = 1.0 + 4.0 * s.position[static_cast<std::size_t>(i)][0];
  EXPECT_LT((lap.full * f).cwiseAbs().maxCoeff(), 1e-9 * 5.0 / 0.01);
}

TEST(Laplacian, QuadraticWithinOnePercentInTheInterior) {
  for (double jitter : {0.0, 0.1}) {
    const double dx = 0.1;
    const auto s = lattice2(14, 14, dx, jitter);
    const CubicSplineKernel<2> kernel(1.2 * dx);
    const auto lap = build_node_laplacian<2>(s, kernel);
    const Eigen::VectorXd Lf = lap.full * sample(s, quadratic);
    double worst = 0.0;
    for (Index i = 0; i < s.size(); ++i) {
      const Vec<2>& x = s.position[static_cast<std::size_t>(i)];
      const double margin = 2.0 * kernel.h() + 0.5 * dx;  // full support
      if (x[0] < margin || x[1] < margin || x[0] > 1.4 - margin || x[1] > 1.4 - margin) continue;
      worst = std::max(worst, std::abs(Lf[i] - 4.0) / 4.0);
    }
    EXPECT_LT(worst, 0.01) << "jitter " << jitter;
    // Edges stay bounded (method-notes §3.5 table: the corrected form is O(1) wrong there, not
    // O(1/dx)).
    EXPECT_LT(Lf.cwiseAbs().maxCoeff(), 40.0);
  }
}

TEST(Laplacian, SymmetricPartIsSymmetricWithZeroRowSums) {
  const auto s = lattice2(8, 6, 0.1, 0.15);
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.12));
  const Eigen::SparseMatrix<double> S = lap.symmetric;
  const Eigen::SparseMatrix<double> St = S.transpose();
  EXPECT_LT((S - St).norm(), 1e-12 * S.norm());
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(s.size());
  EXPECT_LT((lap.symmetric * ones).cwiseAbs().maxCoeff(), 1e-9 * S.norm());
  EXPECT_LT((lap.full * ones).cwiseAbs().maxCoeff(), 1e-9 * S.norm());
  // Off-diagonal entries non-negative: a weighted graph Laplacian (negative semi-definite).
  for (int k = 0; k < lap.symmetric.outerSize(); ++k) {
    for (NodeLaplacian<2>::Sparse::InnerIterator it(lap.symmetric, k); it; ++it) {
      if (it.row() != it.col()) {
        EXPECT_GE(it.value(), 0.0);
      }
    }
  }
}

TEST(Laplacian, WallRowsSeeTheEvenExtension) {
  // f = (x - 1)^2 on [0, 1]: f'(1) = 0 at the right end (a wall), exact Laplacian 2. With the
  // normal gradient zeroed at the wall node the row evaluates the mirrored field.
  ParticleSet<1> s;
  for (int i = 0; i <= 20; ++i) {
    Vec<1> x;
    x[0] = 0.05 * i;
    s.position.push_back(x);
    s.volume.push_back(i == 0 || i == 20 ? 0.025 : 0.05);
    s.density.push_back(1.0);
    s.material.push_back(0);
  }
  std::vector<std::uint8_t> wall(21, 0);
  wall[20] = 1;
  const auto lap = build_node_laplacian<1>(s, CubicSplineKernel<1>(0.06), wall);
  Eigen::VectorXd f(21);
  for (int i = 0; i <= 20; ++i) f[i] = (0.05 * i - 1.0) * (0.05 * i - 1.0);
  const Eigen::VectorXd Lf = lap.full * f;
  EXPECT_NEAR(Lf[20], 2.0, 0.02 * 2.0);
  EXPECT_NEAR(Lf[10], 2.0, 0.01 * 2.0);
}

TEST(Laplacian, MirrorWallsRestoreTheFullSupportIn2D) {
  // f = x^2 + y^2 has zero normal derivative on the walls x = 0 and y = 0: with the walls
  // mirrored, the rows along them (corner excluded: no double images) give 4 like the interior.
  const double dx = 0.1;
  const auto s = lattice2(14, 14, dx, 0.0);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const std::vector<MirrorPlane> walls = {{0, 0.0, -1}, {1, 0.0, -1}};
  const auto lap = build_node_laplacian<2>(s, kernel, {}, walls);
  const auto plain = build_node_laplacian<2>(s, kernel);
  const Eigen::VectorXd Lf = lap.full * sample(s, quadratic);
  const Eigen::VectorXd Pf = plain.full * sample(s, quadratic);
  double worst = 0.0, worst_plain = 0.0;
  for (Index i = 0; i < s.size(); ++i) {
    const Vec<2>& x = s.position[static_cast<std::size_t>(i)];
    const double far = 1.4 - 2.0 * kernel.h() - 0.5 * dx;
    if (x[0] > far || x[1] > far) continue;                            // away from the open sides
    if (x[0] < 2.0 * kernel.h() && x[1] < 2.0 * kernel.h()) continue;  // corner region
    worst = std::max(worst, std::abs(Lf[i] - 4.0) / 4.0);
    worst_plain = std::max(worst_plain, std::abs(Pf[i] - 4.0) / 4.0);
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(worst_plain, 0.1);  // without the mirrors the wall rows are far off (method-notes §3.5)
  // The symmetric part stays symmetric with the images.
  const Eigen::SparseMatrix<double> S = lap.symmetric;
  EXPECT_LT((S - Eigen::SparseMatrix<double>(S.transpose())).norm(), 1e-12 * S.norm());
}

// The pressure filter's two halves S and T G, with G the corrected node gradient as the solver
// builds it (StaggeredSolver::build_saturated).
struct Filter {
  Eigen::SparseMatrix<double, Eigen::RowMajor> S, TG;
};
Filter build_filter(const ParticleSet<2>& s, const CubicSplineKernel<2>& kernel) {
  const auto op = build_corrected_operator<2>(s.position, s, kernel);
  const auto grad = gradient_matrices<2>(op, s.size());
  const auto lap = build_node_laplacian<2>(s, kernel);
  return {lap.symmetric, build_filter_gradient_part<2>(lap.symmetric, s.position, grad)};
}

TEST(PressureFilter, VanishesForLinearFieldsOnJitteredAndTruncatedSets) {
  for (double jitter : {0.0, 0.2}) {
    const double dx = 0.1;
    const auto s = lattice2(10, 10, dx, jitter);
    const auto f = build_filter(s, CubicSplineKernel<2>(1.2 * dx));
    const Eigen::VectorXd p = sample(s, linear);
    // Edges and corners included: a wall carrying a linear pressure is not drained by it.
    EXPECT_LT(((f.S - f.TG) * p).cwiseAbs().maxCoeff(), 1e-9 * 5.0 / (dx * dx)) << "jitter " << jitter;
  }
}

TEST(PressureFilter, VanishesForQuadraticFieldsInsideAndDampsTheCheckerboard) {
  const double dx = 0.1;
  const auto s = lattice2(14, 14, dx, 0.0);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto f = build_filter(s, kernel);
  const Eigen::VectorXd q = (f.S - f.TG) * sample(s, quadratic);  // its Laplacian is 4
  Eigen::VectorXd checker(s.size());
  for (Index i = 0; i < s.size(); ++i) {
    const Vec<2>& x = s.position[static_cast<std::size_t>(i)];
    checker[i] = (std::lround(x[0] / dx) + std::lround(x[1] / dx)) % 2 == 0 ? 1.0 : -1.0;
  }
  const Eigen::VectorXd c = (f.S - f.TG) * checker;
  const Eigen::VectorXd cs = f.S * checker;
  double worst_quadratic = 0.0, weakest_damping = 1e300;
  for (Index i = 0; i < s.size(); ++i) {
    const Vec<2>& x = s.position[static_cast<std::size_t>(i)];
    const double margin = 4.0 * kernel.h() + 0.5 * dx;  // G and then S see full supports
    if (x[0] < margin || x[1] < margin || x[0] > 1.4 - margin || x[1] > 1.4 - margin) continue;
    worst_quadratic = std::max(worst_quadratic, std::abs(q[i]) / 4.0);
    // On the checkerboard the corrected gradient vanishes, so the filter is the Brookshaw
    // Laplacian S itself, pulling each node towards its neighbours' mean (sign opposite to p).
    EXPECT_NEAR(c[i], cs[i], 1e-9 * std::abs(cs[i]));
    weakest_damping = std::min(weakest_damping, -c[i] * checker[i] * dx * dx);
  }
  EXPECT_LT(worst_quadratic, 1e-9);  // exact: psi_IJ = 0 for a quadratic where G is exact
  EXPECT_GT(weakest_damping, 1.0);   // |F p| >~ |p| / dx^2 on the odd-even mode
}

// With the quadratic-exact gradient (solver.pressure_filter_gradient = "quadratic", method-notes
// eq. (2.4.18)) psi_IJ vanishes for quadratic fields on every row, faces and corners of a
// jittered set included, so the filter leaves a drained face's curved pressure alone; the
// linear-exact gradient does not (that is the defect it fixes), and the odd-even mode is still
// damped on every row.
TEST(PressureFilter, QuadraticGradientVanishesForQuadraticFieldsOnEveryRow) {
  for (double jitter : {0.0, 0.2}) {
    const double dx = 0.1;
    const auto s = lattice2(12, 12, dx, jitter);
    const CubicSplineKernel<2> kernel(1.2 * dx);
    const auto op = build_corrected_operator<2>(s.position, s, kernel);
    Index fitted = 0;
    const auto quad = quadratic_exact_gradient<2>(op, s.position, s, kernel, dx, nullptr, &fitted);
    const auto lap = build_node_laplacian<2>(s, kernel);
    const auto tg_linear = build_filter_gradient_part<2>(lap.symmetric, s.position, gradient_matrices<2>(op, s.size()));
    const auto tg_quad = build_filter_gradient_part<2>(lap.symmetric, s.position, gradient_matrices<2>(quad, s.size()));
    // Every row whose support is truncated is fitted; on the regular lattice the full rows are kept.
    EXPECT_GT(fitted, 0);
    if (jitter == 0.0) {
      EXPECT_LT(fitted, s.size());
    }
    const Eigen::VectorXd q = sample(s, quadratic);
    const Eigen::VectorXd lin = sample(s, linear);
    const double scale = 4.0;  // the Laplacian of the quadratic
    const Eigen::VectorXd fq = (lap.symmetric - tg_quad) * q;
    const Eigen::VectorXd fl = (lap.symmetric - tg_linear) * q;
    EXPECT_LT(fq.cwiseAbs().maxCoeff() / scale, 1e-8) << "jitter " << jitter;
    EXPECT_GT(fl.cwiseAbs().maxCoeff() / scale, 0.1) << "jitter " << jitter;  // the linear gradient's defect
    EXPECT_LT(((lap.symmetric - tg_quad) * lin).cwiseAbs().maxCoeff(), 1e-9 * 5.0 / (dx * dx));
    // The checkerboard: still pulled towards its neighbours' mean on every row.
    Eigen::VectorXd checker(s.size());
    for (Index i = 0; i < s.size(); ++i) checker[i] = (i % 13 + i / 13) % 2 == 0 ? 1.0 : -1.0;
    const Eigen::VectorXd c = (lap.symmetric - tg_quad) * checker;
    double weakest = 1e300;
    for (Index i = 0; i < s.size(); ++i) weakest = std::min(weakest, -c[i] * checker[i] * dx * dx);
    EXPECT_GT(weakest, 0.5) << "jitter " << jitter;
  }
}

// Only the selected rows are fitted (the rows near a drained face): a pattern that they share
// with unselected rows (the bottom face's rows left and right of x = 0.5) is split, the
// unselected rows keep the linear-exact weights bit for bit.
TEST(PressureFilter, QuadraticGradientFitsOnlyTheSelectedRows) {
  const double dx = 0.1;
  const auto s = lattice2(12, 12, dx, 0.0);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto op = build_corrected_operator<2>(s.position, s, kernel);
  std::vector<char> select(static_cast<std::size_t>(s.size()), 0);
  for (Index i = 0; i < s.size(); ++i) select[static_cast<std::size_t>(i)] = s.position[static_cast<std::size_t>(i)][0] < 0.55;
  Index fitted = 0;
  const auto quad = quadratic_exact_gradient<2>(op, s.position, s, kernel, dx, &select, &fitted);
  EXPECT_GT(fitted, 0);
  for (Index i = 0; i < s.size(); ++i) {
    const auto& x = s.position[static_cast<std::size_t>(i)];
    // The gradient of x^2 + y^2 at row i from each operator, against 2x.
    Vec<2> g_op = Vec<2>::Zero(), g_quad = Vec<2>::Zero();
    const auto ro = op.row(i), rq = quad.row(i);
    ASSERT_EQ(ro.end - ro.begin, rq.end - rq.begin);
    for (Index k = 0; k < ro.end - ro.begin; ++k) {
      const double f = quadratic(s.position[static_cast<std::size_t>(op.source(ro, ro.begin + k))]);
      ASSERT_EQ(op.source(ro, ro.begin + k), quad.source(rq, rq.begin + k));
      for (int d = 0; d < 2; ++d) {
        g_op[d] += op.grad[static_cast<std::size_t>(ro.begin + k)][static_cast<std::size_t>(d)] * f;
        g_quad[d] += quad.grad[static_cast<std::size_t>(rq.begin + k)][static_cast<std::size_t>(d)] * f;
      }
    }
    if (select[static_cast<std::size_t>(i)] != 0) {
      EXPECT_LT((g_quad - 2.0 * x).norm(), 1e-9) << "row " << i;
    } else {
      EXPECT_EQ(g_quad, g_op) << "row " << i;
    }
  }
}

// The odd-even amplitude (method-notes eq. (2.4.19)): the pure mode on every determined row,
// zero on quadratic fields, on a regular and a jittered lattice.
TEST(OddEvenAmplitude, IsTheModeOnTheModeAndZeroOnQuadratics) {
  for (double jitter : {0.0, 0.2}) {
    const double dx = 0.1;
    const auto s = lattice2(12, 12, dx, jitter);
    const CubicSplineKernel<2> kernel(1.2 * dx);
    const auto op = build_corrected_operator<2>(s.position, s, kernel);
    Index undetermined = -1;
    const auto oe = odd_even_amplitude<2>(op, s.position, s, kernel, dx, &undetermined);
    EXPECT_EQ(undetermined, 0) << "jitter " << jitter;
    auto amplitude = [&](const Eigen::VectorXd& p, Index i) {
      double a = 0.0;
      const auto r = op.row(i);
      for (Index k = r.begin; k < r.end; ++k) a += oe[static_cast<std::size_t>(k)] * p[op.source(r, k)];
      return a;
    };
    // The three odd-even modes of a 2D lattice: along x, along y, and the checkerboard.
    Eigen::VectorXd mode_x(s.size()), mode_y(s.size()), checker(s.size());
    for (Index i = 0; i < s.size(); ++i) {
      mode_x[i] = (i % 13) % 2 == 0 ? 1.0 : -1.0;
      mode_y[i] = (i / 13) % 2 == 0 ? 1.0 : -1.0;
      checker[i] = mode_x[i] * mode_y[i];
    }
    const Eigen::VectorXd q = sample(s, quadratic), lin = sample(s, linear);
    for (Index i = 0; i < s.size(); ++i) {
      EXPECT_NEAR(amplitude(checker, i), checker[i], 1e-9) << "row " << i << " jitter " << jitter;
      // The axis modes on every row that spans three levels beyond itself along both axes (two
      // rows in from each face); nearer a face the mode normal to it is a parabola there.
      const Index ix = i % 13, iy = i / 13;
      if (ix >= 2 && ix <= 10 && iy >= 2 && iy <= 10) {
        EXPECT_NEAR(amplitude(mode_x, i), mode_x[i], 1e-9) << "row " << i << " jitter " << jitter;
        EXPECT_NEAR(amplitude(mode_y, i), mode_y[i], 1e-9) << "row " << i << " jitter " << jitter;
      }
      EXPECT_NEAR(amplitude(q, i), 0.0, 1e-9) << "row " << i << " jitter " << jitter;
      EXPECT_NEAR(amplitude(lin, i), 0.0, 1e-9) << "row " << i << " jitter " << jitter;
    }
  }
}

// Where the corrected gradient is already exact for quadratics (a full support on a lattice)
// its weights are kept bit for bit.
TEST(PressureFilter, QuadraticGradientKeepsTheInteriorWeights) {
  const double dx = 0.1;
  const auto s = lattice2(14, 14, dx, 0.0);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto op = build_corrected_operator<2>(s.position, s, kernel);
  const auto quad = quadratic_exact_gradient<2>(op, s.position, s, kernel, dx);
  ASSERT_EQ(quad.grad.size(), op.grad.size());
  const Index centre = 7 * 15 + 7;  // a 15 x 15 lattice
  const auto r = op.row(centre);
  for (Index k = r.begin; k < r.end; ++k) {
    EXPECT_EQ(quad.grad[static_cast<std::size_t>(k)][0], op.grad[static_cast<std::size_t>(k)][0]);
    EXPECT_EQ(quad.grad[static_cast<std::size_t>(k)][1], op.grad[static_cast<std::size_t>(k)][1]);
  }
}

}  // namespace
}  // namespace rktsph
