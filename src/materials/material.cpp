#include "materials/material.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/section.hpp"

namespace rktsph {

ElasticConstants ElasticConstants::from_E_nu(double E, double nu, double density) {
  ElasticConstants c;
  c.E = E;
  c.nu = nu;
  c.density = density;
  c.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  c.G = E / (2.0 * (1.0 + nu));
  c.K = E / (3.0 * (1.0 - 2.0 * nu));
  c.M = c.lambda + 2.0 * c.G;
  return c;
}

double ElasticConstants::p_wave_speed() const { return std::sqrt((K + 4.0 * G / 3.0) / density); }

Sym6 ElasticConstants::apply(const Sym6& e) const {
  const double tr = e[0] + e[1] + e[2];
  return {lambda * tr + 2.0 * G * e[0], lambda * tr + 2.0 * G * e[1], lambda * tr + 2.0 * G * e[2],
          2.0 * G * e[3], 2.0 * G * e[4], 2.0 * G * e[5]};
}

Sym6 ElasticConstants::apply_inverse(const Sym6& s) const {
  const double tr = s[0] + s[1] + s[2];
  const double a = -nu / E * tr;
  const double b = (1.0 + nu) / E;
  return {a + b * s[0], a + b * s[1], a + b * s[2], b * s[3], b * s[4], b * s[5]};
}

void Material::source_rate(const Sym6& /*sigma*/, const double* /*state*/, Sym6& dsigma,
                           double* dstate) const {
  dsigma.fill(0.0);
  for (int i = 0; i < state_size(); ++i) dstate[i] = 0.0;
}

double Material::relaxation_rate(const Sym6& /*sigma*/, const double* /*state*/) const {
  return 0.0;
}

SourceStats Material::advance_source(double tau, const SourceBatch& b) const {
  const int ns = b.stress_components;
  const int nk = state_size();
  SourceStats stats;
  // Scratch for the RK4 stages; a model carries at most a handful of history variables.
  constexpr int kMaxState = 16;
  if (nk > kMaxState) throw SolverError("material carries too many history variables");
  for (std::size_t i = 0; i < b.count; ++i) {
    const double* s0p = b.sigma_start + i * b.sigma_start_stride;
    Sym6 s0{};
    for (int c = 0; c < ns; ++c) s0[static_cast<std::size_t>(c)] = s0p[c];
    Sym6 rate{};
    if (b.flux_rate != nullptr) {
      const double* rp = b.flux_rate + i * b.flux_rate_stride;
      for (int c = 0; c < ns; ++c) rate[static_cast<std::size_t>(c)] = rp[c];
    }
    const double* k0 = b.state_start + static_cast<std::size_t>(nk) * i;
    double* k_end = b.state_end + static_cast<std::size_t>(nk) * i;
    const bool frozen = b.coupling == SourceCoupling::frozen_flux;
    const double lam = relaxation_rate(s0, k0);
    long substeps = std::max(1L, static_cast<long>(std::ceil(lam * tau / rk4_stability_target)));
    if (substeps > max_substeps) {
      throw SolverError(fmt::format(
          "the viscoplastic source is too stiff: relaxation rate {:.3g} 1/s needs {} RK4 "
          "sub-steps per step (limit {}); reduce the fluidity or the time step",
          lam, substeps, max_substeps));
    }
    stats.max_substeps = std::max(stats.max_substeps, substeps);
    stats.total_substeps += substeps;
    const double dt = tau / static_cast<double>(substeps);
    Sym6 s = s0;
    double k[kMaxState];
    for (int j = 0; j < nk; ++j) k[j] = k0[j];
    Sym6 ds[4];
    double dk[4][kMaxState];
    Sym6 st;
    double kt[kMaxState];
    for (long sub = 0; sub < substeps; ++sub) {
      // Classical RK4 stages (METHOD.md §2.2); the frozen flux rate joins the ODE when chosen.
      const double frac[4] = {0.0, 0.5, 0.5, 1.0};
      for (int stage = 0; stage < 4; ++stage) {
        for (std::size_t c = 0; c < 6; ++c) st[c] = stage == 0 ? s[c] : s[c] + frac[stage] * dt * ds[stage - 1][c];
        for (int j = 0; j < nk; ++j) kt[j] = stage == 0 ? k[j] : k[j] + frac[stage] * dt * dk[stage - 1][j];
        source_rate(st, kt, ds[stage], dk[stage]);
        if (frozen) {
          for (std::size_t c = 0; c < 6; ++c) ds[stage][c] += rate[c];
        }
      }
      for (std::size_t c = 0; c < 6; ++c) {
        s[c] += dt / 6.0 * (ds[0][c] + 2.0 * ds[1][c] + 2.0 * ds[2][c] + ds[3][c]);
      }
      for (int j = 0; j < nk; ++j) {
        k[j] += dt / 6.0 * (dk[0][j] + 2.0 * dk[1][j] + 2.0 * dk[2][j] + dk[3][j]);
      }
    }
    double* se = b.sigma_end + i * b.sigma_end_stride;
    for (int c = 0; c < ns; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      // Additive form: flux increment and source increment from the same start state.
      se[c] = frozen ? s[cc] : s[cc] + tau * rate[cc];
    }
    for (int j = 0; j < nk; ++j) k_end[j] = k[j];
  }
  return stats;
}

ElasticConstants read_elastic_constants(const io::Section& s) {
  const double E = s.number("E");
  s.require(E > 0.0, "E", fmt::format("Young's modulus must be > 0 Pa, got {}", E));
  const double nu = s.number("nu");
  s.require(nu > -1.0 && nu < 0.5, "nu",
            fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", nu));
  const double rho = s.number("density");
  s.require(rho > 0.0, "density", fmt::format("density must be > 0 kg/m^3, got {}", rho));
  return ElasticConstants::from_E_nu(E, nu, rho);
}

}  // namespace rktsph
