#pragma once
// RK4 integration of the pointwise source ODE for a batch of particles (method-notes §2.2,
// §4.3), written once as a template so that a model can call it with its non-virtual rate
// (the fast path of PerzynaMaterial) while Material::advance_source calls it through the
// virtual interface.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include <fmt/format.h>

#include "core/error.hpp"
#include "materials/material.hpp"

namespace rktsph::detail {

/// rate(sigma, state, dsigma, dstate) is the source rate; relax(sigma, state) its relaxation
/// rate estimate in 1/s. nk is the number of history variables per particle.
template <class RateFn, class RelaxFn>
SourceStats integrate_source_batch(double tau, const SourceBatch& b, int nk, RateFn&& rate, RelaxFn&& relax) {
  constexpr int kMaxState = 16;  // a model carries at most a handful of history variables
  if (nk > kMaxState) throw SolverError("material carries too many history variables");
  const int ns = b.stress_components;
  const bool frozen = b.coupling == SourceCoupling::frozen_flux;
  const std::size_t kstride = b.state_stride != 0 ? b.state_stride : static_cast<std::size_t>(nk);
  SourceStats stats;
  for (std::size_t i = 0; i < b.count; ++i) {
    const double* s0p = b.sigma_start + i * b.sigma_start_stride;
    Sym6 s{};
    for (int c = 0; c < ns; ++c) s[static_cast<std::size_t>(c)] = s0p[c];
    Sym6 r{};
    if (b.flux_rate != nullptr) {
      const double* rp = b.flux_rate + i * b.flux_rate_stride;
      for (int c = 0; c < ns; ++c) r[static_cast<std::size_t>(c)] = rp[c];
    }
    const double* k0 = b.state_start + kstride * i;
    double k[kMaxState];
    for (int j = 0; j < nk; ++j) k[j] = k0[j];

    // The relaxation rate is zero inside the surface; with the frozen flux the loading R can
    // carry an elastic start far outside within the step, so also look at the elastic
    // trial end point s0 + tau R (method-notes §4.3).
    double lam = relax(s, k);
    if (frozen) {
      Sym6 trial;
      for (std::size_t c = 0; c < 6; ++c) trial[c] = s[c] + tau * r[c];
      lam = std::max(lam, relax(trial, k));
    }
    const double want = std::ceil(lam * tau / Material::rk4_stability_target);
    if (!(want <= static_cast<double>(Material::max_substeps))) {
      throw SolverError(
          fmt::format("the viscoplastic source is too stiff: relaxation rate {:.3g} 1/s needs {:.3g} RK4 "
                      "sub-steps per step (limit {}); reduce the fluidity or the time step",
                      lam, want, Material::max_substeps));
    }
    const long substeps = std::max(1L, static_cast<long>(want));
    stats.max_substeps = std::max(stats.max_substeps, substeps);
    stats.total_substeps += substeps;
    const double h = tau / static_cast<double>(substeps);

    Sym6 ds[4];
    double dk[4][kMaxState];
    Sym6 st;
    double kt[kMaxState];
    constexpr double kFrac[4] = {0.0, 0.5, 0.5, 1.0};
    for (long sub = 0; sub < substeps; ++sub) {
      // Classical RK4 stages; the frozen flux rate joins the ODE when chosen (method-notes §2.2).
      for (int stage = 0; stage < 4; ++stage) {
        if (stage == 0) {
          st = s;
          for (int j = 0; j < nk; ++j) kt[j] = k[j];
        } else {
          const double a = kFrac[stage] * h;
          for (std::size_t c = 0; c < 6; ++c) st[c] = s[c] + a * ds[stage - 1][c];
          for (int j = 0; j < nk; ++j) kt[j] = k[j] + a * dk[stage - 1][j];
        }
        rate(st, kt, ds[stage], dk[stage]);
        if (frozen) {
          for (std::size_t c = 0; c < 6; ++c) ds[stage][c] += r[c];
        }
      }
      for (std::size_t c = 0; c < 6; ++c) {
        s[c] += h / 6.0 * (ds[0][c] + 2.0 * ds[1][c] + 2.0 * ds[2][c] + ds[3][c]);
      }
      for (int j = 0; j < nk; ++j) {
        k[j] += h / 6.0 * (dk[0][j] + 2.0 * dk[1][j] + 2.0 * dk[2][j] + dk[3][j]);
      }
    }
    double* se = b.sigma_end + i * b.sigma_end_stride;
    for (int c = 0; c < ns; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      // Additive form: flux increment and source increment from the same start state.
      se[c] = frozen ? s[cc] : s[cc] + tau * r[cc];
    }
    double* k_end = b.state_end + kstride * i;
    for (int j = 0; j < nk; ++j) k_end[j] = k[j];
  }
  return stats;
}

}  // namespace rktsph::detail
