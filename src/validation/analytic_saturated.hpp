#pragma once
// Closed-form references of the saturated (V3) validation cases (docs/cases.md Cases 13 and 14),
// for the u-p_w model (C4) in one dimension. z is the depth from the drained, loaded top.
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Dense>

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

/// Terzaghi consolidation (docs/cases.md Case 13) under a load ramped linearly from 0 to q over
/// `ramp` seconds (exact convolution of the step solution with the ramp; ramp = 0: a step).
struct Terzaghi {
  SaturatedColumn col;
  double load = 0.0;  // q, Pa (compression positive)
  double ramp = 0.0;  // s

  // Ramp average of exp(-a (t - s)) over the loading history, times the load fraction.
  double ramp_factor(double a, double t) const {
    if (ramp <= 0.0) return std::exp(-a * t);
    if (t <= 0.0) return 0.0;
    if (t < ramp) return -std::expm1(-a * t) / (a * ramp);
    return std::exp(-a * (t - ramp)) * (-std::expm1(-a * ramp)) / (a * ramp);
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
    const double fraction = ramp > 0.0 ? std::min(t / ramp, 1.0) : 1.0;
    return fraction > 0.0 ? 1.0 - s / fraction : 0.0;
  }
  /// Settlement S(t) = S0 + (S_inf - S0) U, with the ramp, m.
  double settlement(double t) const {
    const double fraction = ramp > 0.0 ? std::min(t / ramp, 1.0) : 1.0;
    const double s0 = load * col.height / (col.constrained + col.storage);
    const double sinf = load * col.height / col.constrained;
    return fraction * (s0 + (sinf - s0) * degree(t));
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

}  // namespace rktsph::analytic
