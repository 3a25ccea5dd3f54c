// Cubic B-spline kernel (method-notes §3.1): normalisation, derivative, support, gradient.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/kernel.hpp"

namespace rktsph {
namespace {

// Composite Simpson rule on [a, b] with n (even) intervals.
template <class F>
double simpson(F&& f, double a, double b, int n) {
  const double step = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 == 1 ? 4.0 : 2.0) * f(a + i * step);
  return s * step / 3.0;
}

TEST(CubicSplineKernel, IntegratesToOneIn1D) {
  for (double h : {0.1, 1.0, 3.7}) {
    const CubicSplineKernel<1> k(h);
    // The kernel is piecewise cubic with breaks at r = h, 2h: Simpson on each piece is exact.
    const double integral = 2.0 * (simpson([&](double r) { return k.value(r); }, 0.0, h, 2) +
                                   simpson([&](double r) { return k.value(r); }, h, 2.0 * h, 2));
    EXPECT_NEAR(integral, 1.0, 1e-13) << "h = " << h;
  }
}

TEST(CubicSplineKernel, IntegratesToOneIn2D) {
  for (double h : {0.1, 1.0, 2.5}) {
    const CubicSplineKernel<2> k(h);
    // Radial integral 2 pi \int W r dr (the integrand is a quartic per piece: Simpson with
    // refinement is accurate to ~1e-12).
    auto f = [&](double r) { return 2.0 * std::numbers::pi * r * k.value(r); };
    const double integral = simpson(f, 0.0, h, 2000) + simpson(f, h, 2.0 * h, 2000);
    EXPECT_NEAR(integral, 1.0, 1e-12) << "h = " << h;
  }
}

TEST(CubicSplineKernel, IntegratesToOneIn2DOnALattice) {
  // Independent of the radial formula: a Cartesian midpoint sum over a fine lattice.
  const double h = 1.0;
  const CubicSplineKernel<2> k(h);
  const double d = 0.01;
  double sum = 0.0;
  for (int i = -250; i < 250; ++i) {
    for (int j = -250; j < 250; ++j) {
      const double x = (i + 0.5) * d, y = (j + 0.5) * d;
      sum += k.value(std::hypot(x, y)) * d * d;
    }
  }
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

TEST(CubicSplineKernel, IntegratesToOneIn3D) {
  const double h = 0.7;
  const CubicSplineKernel<3> k(h);
  auto f = [&](double r) { return 4.0 * std::numbers::pi * r * r * k.value(r); };
  EXPECT_NEAR(simpson(f, 0.0, h, 2000) + simpson(f, h, 2.0 * h, 2000), 1.0, 1e-10);
}

TEST(CubicSplineKernel, DerivativeMatchesFiniteDifferences) {
  const double h = 1.3;
  const CubicSplineKernel<2> k(h);
  const double eps = 1e-6;
  for (double q = 0.01; q < 2.2; q += 0.0731) {
    const double r = q * h;
    if (std::abs(q - 1.0) < 1e-3 || std::abs(q - 2.0) < 1e-3) continue;
    const double fd = (k.value(r + eps) - k.value(r - eps)) / (2.0 * eps);
    EXPECT_NEAR(k.derivative(r), fd, 1e-7 * (1.0 + std::abs(fd))) << "q = " << q;
  }
  // Continuity of W and W' at the branch point q = 1 and at the support edge.
  EXPECT_NEAR(k.value(h * (1 - 1e-12)), k.value(h * (1 + 1e-12)), 1e-10);
  EXPECT_NEAR(k.derivative(h * (1 - 1e-12)), k.derivative(h * (1 + 1e-12)), 1e-10);
  EXPECT_NEAR(k.derivative(0.0), 0.0, 0.0);
}

TEST(CubicSplineKernel, CompactSupportIsTwoH) {
  const double h = 0.4;
  const CubicSplineKernel<1> k(h);
  EXPECT_DOUBLE_EQ(k.support_radius(), 2.0 * h);
  EXPECT_GT(k.value(2.0 * h * (1.0 - 1e-3)), 0.0);
  EXPECT_LT(k.derivative(2.0 * h * (1.0 - 1e-3)), 0.0);
  EXPECT_EQ(k.value(2.0 * h), 0.0);
  EXPECT_EQ(k.value(2.0 * h * 1.0001), 0.0);
  EXPECT_EQ(k.derivative(2.0 * h), 0.0);
  EXPECT_EQ(k.value(10.0), 0.0);
  // Monotone decreasing inside the support.
  for (double r = 0.0; r < 2.0 * h - 0.01; r += 0.01) EXPECT_GT(k.value(r), k.value(r + 0.01));
}

TEST(CubicSplineKernel, GradientIsAntisymmetricAndRadial) {
  const CubicSplineKernel<2> k(0.5);
  const Vec<2> xa(0.3, -0.1), xb(0.1, 0.35);
  const Vec<2> gab = k.gradient(xa - xb), gba = k.gradient(xb - xa);
  EXPECT_GT(gab.norm(), 0.0);
  EXPECT_NEAR((gab + gba).norm(), 0.0, 1e-15);
  // Along x_ab, and it points from a towards b (W decreases with distance).
  const Vec<2> xab = xa - xb;
  EXPECT_NEAR(gab.x() * xab.y() - gab.y() * xab.x(), 0.0, 1e-14);
  EXPECT_LT(gab.dot(xab), 0.0);
  EXPECT_NEAR(gab.norm(), std::abs(k.derivative(xab.norm())), 1e-14);
  // Finite differences of W(|x_a - x_b|) with respect to x_a.
  const double eps = 1e-6;
  for (int d = 0; d < 2; ++d) {
    Vec<2> e = Vec<2>::Zero();
    e[d] = eps;
    const double fd = (k.value((xab + e).norm()) - k.value((xab - e).norm())) / (2 * eps);
    EXPECT_NEAR(gab[d], fd, 1e-7);
  }
  EXPECT_EQ(k.gradient(Vec<2>::Zero()).norm(), 0.0);
}

}  // namespace
}  // namespace rktsph
