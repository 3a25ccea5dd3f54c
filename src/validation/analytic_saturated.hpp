#pragma once
// Closed-form references of the saturated (V3) validation cases (docs/cases.md Cases 13 and 14),
// for the u-p_w model (C4) in one dimension (z is the depth from the drained, loaded top), and
// Mandel's problem in plane strain (cases/examples/mandel_2d.toml).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Dense>

#include "bc/time_function.hpp"

namespace rktsph::analytic {

/// Column constants shared by both cases (docs/cases.md C4 and Case 13).
struct SaturatedColumn {
  double height = 10.0;       // H = L, m
  double constrained = 0.0;   // drained constrained modulus M, Pa
  double storage = 0.0;       // Q with 1/Q = n/K_f, Pa
  double permeability = 0.0;  // k_w = k/gamma_w, m^3 s/kg
  double density = 0.0;       // mixture density rho, kg/m^3

  /// Undrained pore pressure per unit load, Q/(M+Q).
  double skempton() const { return storage / (constrained + storage); }
  /// Biot's coefficient of consolidation c_v = k_w / (1/M + 1/Q), m^2/s.
  double cv() const { return permeability / (1.0 / constrained + 1.0 / storage); }
  double time_factor(double t) const { return cv() * t / (height * height); }
};

/// Terzaghi consolidation (docs/cases.md Case 13) under a load raised from 0 to q over `ramp`
/// seconds, linearly or by the quintic smoothstep S(s) = 10 s^3 - 15 s^4 + 6 s^5 (the case
/// file's "ramp" and "smoothstep" functions): the step solution convolved exactly with the load
/// history (ramp = 0: a step).
struct Terzaghi {
  SaturatedColumn col;
  double load = 0.0;  // q, Pa (compression positive)
  double ramp = 0.0;  // s
  /// The rise: TimeFunction::Kind::ramp (linear) or ::smoothstep.
  TimeFunction::Kind rise = TimeFunction::Kind::ramp;

  /// Load fraction f(t) in [0, 1], the case file's function itself.
  double fraction(double t) const {
    if (ramp <= 0.0) return t >= 0.0 ? 1.0 : 0.0;
    return (rise == TimeFunction::Kind::smoothstep ? TimeFunction::smoothstep(ramp) : TimeFunction::ramp(ramp))(t);
  }

  /// The load history's weight on exp(-a (t - tau)): the integral of f'(tau) exp(-a (t - tau))
  /// over 0 <= tau <= t (the mode's response to the history, per unit load).
  double ramp_factor(double a, double t) const {
    if (ramp <= 0.0) return std::exp(-a * t);
    if (t <= 0.0) return 0.0;
    if (rise != TimeFunction::Kind::smoothstep) {
      if (t < ramp) return -std::expm1(-a * t) / (a * ramp);
      return std::exp(-a * (t - ramp)) * (-std::expm1(-a * ramp)) / (a * ramp);
    }
    // Smoothstep: f'(tau) = g(s)/ramp with g(s) = 30 s^2 (1 - s)^2, s = tau/ramp. In s the
    // integral is that of g(s) exp(-b (theta - s)) over [0, m], b = a ramp, theta = t/ramp.
    const double b = a * ramp, theta = t / ramp, m = std::min(theta, 1.0);
    auto g = [](double s) { return 30.0 * s * s * (1.0 - s) * (1.0 - s); };
    if (b < 1.0) {
      // Small b: Gauss-Legendre on [0, m] (10 points: exact for degree 19; the exponential's
      // Taylor tail beyond that is below 1e-16 for b < 1).
      const auto& gl = gauss_legendre10();
      double sum = 0.0;
      for (std::size_t k = 0; k < gl.size(); ++k) {
        const double s = 0.5 * m * (1.0 + gl[k][0]);
        sum += gl[k][1] * g(s) * std::exp(-b * (theta - s));
      }
      return 0.5 * m * sum;
    }
    // b >= 1: integrate by parts to the end, e^{bs} sum_k (-1)^k g^(k)(s) / b^(k+1) (g is a
    // quartic), without the cancellation that the same sum suffers at small b.
    auto derivatives = [](double s) {
      return std::array<double, 5>{30.0 * s * s * (1.0 - s) * (1.0 - s), 60.0 * s - 180.0 * s * s + 120.0 * s * s * s,
                                   60.0 - 360.0 * s + 360.0 * s * s, -360.0 + 720.0 * s, 720.0};
    };
    const auto dm = derivatives(m), d0 = derivatives(0.0);
    const double em = std::exp(-b * (theta - m)), e0 = std::exp(-b * theta);
    double sum = 0.0, bk = b, sign = 1.0;
    for (std::size_t k = 0; k < 5; ++k, bk *= b, sign = -sign) sum += sign * (dm[k] * em - d0[k] * e0) / bk;
    return sum;
  }

  /// Nodes (on [-1, 1]) and weights of the 10-point Gauss-Legendre rule, by Newton's iteration
  /// on P_10.
  static const std::array<std::array<double, 2>, 10>& gauss_legendre10() {
    static const std::array<std::array<double, 2>, 10> rule = [] {
      std::array<std::array<double, 2>, 10> r{};
      constexpr int n = 10;
      for (int i = 0; i < n; ++i) {
        double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 0.0;
        for (int it = 0; it < 100; ++it) {
          double p0 = 1.0, p1 = x;
          for (int k = 2; k <= n; ++k) {
            const double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
            p0 = p1;
            p1 = pk;
          }
          dp = n * (x * p1 - p0) / (x * x - 1.0);
          const double dx = p1 / dp;
          x -= dx;
          if (std::abs(dx) < 1e-16) break;
        }
        r[static_cast<std::size_t>(i)] = {x, 2.0 / ((1.0 - x * x) * dp * dp)};
      }
      return r;
    }();
    return rule;
  }
  /// p_w(z, t), Pa.
  double pressure(double z, double t) const {
    const double H = col.height, p0 = load * col.skempton();
    double s = 0.0;
    for (int m = 0; m < 400; ++m) {
      const double Mm = (2 * m + 1) * std::numbers::pi / 2.0;
      const double a = Mm * Mm * col.cv() / (H * H);
      s += 2.0 / Mm * std::sin(Mm * z / H) * ramp_factor(a, t);
    }
    return p0 * s;
  }
  /// Degree of consolidation U(t) = 1 - (mean p_w)/(p0 * load fraction).
  double degree(double t) const {
    const double H = col.height;
    double s = 0.0;
    for (int m = 0; m < 400; ++m) {
      const double Mm = (2 * m + 1) * std::numbers::pi / 2.0;
      const double a = Mm * Mm * col.cv() / (H * H);
      s += 2.0 / (Mm * Mm) * ramp_factor(a, t);
    }
    const double f = fraction(t);
    return f > 0.0 ? 1.0 - s / f : 0.0;
  }
  /// Settlement S(t) = S0 + (S_inf - S0) U, with the ramp, m.
  double settlement(double t) const {
    const double f = fraction(t);
    const double s0 = load * col.height / (col.constrained + col.storage);
    const double sinf = load * col.height / col.constrained;
    return f * (s0 + (sinf - s0) * degree(t));
  }
  double final_settlement() const { return load * col.height / col.constrained; }
};

/// Exact steady state of the harmonically loaded column (docs/cases.md Case 14): top z = 0 drained
/// and loaded by the total compressive stress q0 e^{i omega t}; base z = L fixed, impermeable.
/// u is the downward displacement.
struct HarmonicColumn {
  using C = std::complex<double>;
  SaturatedColumn col;
  double omega = 0.0;  // rad/s
  double q0 = 0.0;     // Pa
  std::array<C, 2> s{};
  std::array<C, 4> coef{};  // A_1, A_2, B_1, B_2

  HarmonicColumn(const SaturatedColumn& c, double w, double q) : col(c), omega(w), q0(q) {
    const double M = col.constrained, Q = col.storage, k = col.permeability, rho = col.density, L = col.height;
    const C i(0.0, 1.0);
    // k M lambda^2 - [i w (1 + M/Q) - k rho w^2] lambda - i rho w^3 / Q = 0
    const C a = k * M;
    const C b = -(i * omega * (1.0 + M / Q) - k * rho * omega * omega);
    const C cc = -i * rho * omega * omega * omega / Q;
    const C disc = std::sqrt(b * b - 4.0 * a * cc);
    const std::array<C, 2> lam = {(-b + disc) / (2.0 * a), (-b - disc) / (2.0 * a)};
    for (int j = 0; j < 2; ++j) {
      s[static_cast<std::size_t>(j)] = std::sqrt(lam[static_cast<std::size_t>(j)]);
      if (s[static_cast<std::size_t>(j)].real() < 0.0) s[static_cast<std::size_t>(j)] = -s[static_cast<std::size_t>(j)];
    }
    auto r = [&](C sj) { return sj / (M * sj * sj + rho * omega * omega); };
    Eigen::Matrix<C, 4, 4> A;
    Eigen::Matrix<C, 4, 1> rhs;
    for (int j = 0; j < 2; ++j) {
      const C sj = s[static_cast<std::size_t>(j)];
      const C eA0 = std::exp(-sj * L);  // e^{s(z-L)} at z = 0
      // P(0) = 0
      A(0, j) = eA0;
      A(0, 2 + j) = 1.0;
      // M U'(0) = -q0
      A(1, j) = M * r(sj) * sj * eA0;
      A(1, 2 + j) = M * r(-sj) * (-sj);
      // U(L) = 0
      A(2, j) = r(sj);
      A(2, 2 + j) = r(-sj) * std::exp(-sj * L);
      // P'(L) = 0
      A(3, j) = sj;
      A(3, 2 + j) = -sj * std::exp(-sj * L);
    }
    rhs << 0.0, -q0, 0.0, 0.0;
    const Eigen::Matrix<C, 4, 1> x = A.fullPivLu().solve(rhs);
    for (int j = 0; j < 4; ++j) coef[static_cast<std::size_t>(j)] = x(j);
  }
  C pressure(double z) const {
    C p = 0.0;
    for (std::size_t j = 0; j < 2; ++j) {
      p += coef[j] * std::exp(s[j] * (z - col.height)) + coef[2 + j] * std::exp(-s[j] * z);
    }
    return p;
  }
  C displacement(double z) const {
    const double M = col.constrained, rho = col.density;
    auto r = [&](C sj) { return sj / (M * sj * sj + rho * omega * omega); };
    C u = 0.0;
    for (std::size_t j = 0; j < 2; ++j) {
      u += r(s[j]) * coef[j] * std::exp(s[j] * (z - col.height)) + r(-s[j]) * coef[2 + j] * std::exp(-s[j] * z);
    }
    return u;
  }
};

/// Mandel's problem (Mandel 1953; the series of Abousleiman et al. 1996, Cheng 2016 §7.8): a
/// plane-strain sample -a <= x <= a between rigid, smooth, impermeable plates pressed together by
/// the force 2F (F per half plate, N/m, compression positive), drained and traction-free at
/// x = +-a; incompressible constituents' grains (Biot alpha = 1), fluid storage 1/M. The load is
/// ramped from 0 over `ramp` seconds (exact convolution of the step solution; 0: a step).
struct Mandel {
  double E = 0.0, nu = 0.0;   // drained skeleton
  double storage = 0.0;       // M = Q* (1/M = n/K_f), Pa
  double permeability = 0.0;  // k_w = k / gamma_w, m^3 s/kg
  double half_width = 1.0;    // a, m
  double force = 0.0;         // F, N/m
  double ramp = 0.0;          // s
  static constexpr int kTerms = 200;

  double shear() const { return E / (2.0 * (1.0 + nu)); }
  double bulk() const { return E / (3.0 * (1.0 - 2.0 * nu)); }
  double skempton() const { return storage / (bulk() + storage); }
  double undrained_nu() const {
    const double ku = bulk() + storage, g = shear();
    return (3.0 * ku - 2.0 * g) / (2.0 * (3.0 * ku + g));
  }
  /// Consolidation coefficient c = k_w M (K + 4G/3) / (K_u + 4G/3), m^2/s.
  double consolidation() const {
    const double m43 = 4.0 * shear() / 3.0;
    return permeability * storage * (bulk() + m43) / (bulk() + storage + m43);
  }
  /// The undrained centre pressure F B (1 + nu_u) / (3 a) at t = 0+, Pa.
  double initial_pressure() const { return force * skempton() * (1.0 + undrained_nu()) / (3.0 * half_width); }
  /// The roots alpha_n of tan(alpha) = (1 - nu)/(nu_u - nu) alpha in (n pi, n pi + pi/2).
  std::array<double, kTerms> roots() const {
    std::array<double, kTerms> r{};
    const double k = (1.0 - nu) / (undrained_nu() - nu);
    for (int n = 0; n < kTerms; ++n) {
      double lo = n * std::numbers::pi + 1e-12, hi = n * std::numbers::pi + std::numbers::pi / 2.0 - 1e-12;
      if (n == 0) lo = 1e-9;  // tan(x) - k x < 0 just above 0 (k > 1)
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((std::tan(mid) - k * mid) < 0.0) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      r[static_cast<std::size_t>(n)] = 0.5 * (lo + hi);
    }
    return r;
  }
  // The ramp's average of exp(-l (t - s)) over the loading history, times the load fraction.
  double ramp_factor(double l, double t) const {
    if (ramp <= 0.0) return std::exp(-l * t);
    if (t <= 0.0) return 0.0;
    if (t < ramp) return -std::expm1(-l * t) / (l * ramp);
    return std::exp(-l * (t - ramp)) * (-std::expm1(-l * ramp)) / (l * ramp);
  }
  double load_fraction(double t) const { return ramp > 0.0 ? std::clamp(t / ramp, 0.0, 1.0) : (t > 0.0 ? 1.0 : 0.0); }
  /// p_w(x, t), Pa.
  double pressure(double x, double t) const {
    const double a = half_width, rate = consolidation() / (a * a);
    double s = 0.0;
    for (const double al : roots()) {
      const double sc = std::sin(al) * std::cos(al);
      s += std::sin(al) / (al - sc) * (std::cos(al * x / a) - std::cos(al)) * ramp_factor(al * al * rate, t);
    }
    return 2.0 * initial_pressure() * s;
  }
  /// The plates' approach per unit half height, -u_y(b, t)/b (positive in compression).
  double strain(double t) const {
    const double a = half_width, g = shear(), nuu = undrained_nu(), rate = consolidation() / (a * a);
    double s = 0.0;
    for (const double al : roots()) {
      const double sc = std::sin(al) * std::cos(al);
      s += sc / (al - sc) * ramp_factor(al * al * rate, t);
    }
    return force * (1.0 - nu) / (2.0 * g * a) * load_fraction(t) - force * (1.0 - nuu) / (g * a) * s;
  }
};

/// The constants of cases/examples/mandel_2d.toml (a = 1 m, q = 10 kPa ramped over 0.05 s).
inline Mandel mandel_example() {
  Mandel m;
  m.E = 1.0e7;
  m.nu = 0.2;
  m.storage = 2.2e9 / 0.4;
  m.permeability = 8.846836e-5 / (1000.0 * 9.81);
  m.half_width = 1.0;
  m.force = 1.0e4;
  m.ramp = 0.05;
  return m;
}

}  // namespace rktsph::analytic
