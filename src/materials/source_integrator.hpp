#pragma once
// Integration of the pointwise source ODE for a batch of particles (method-notes §2.2, §2.5,
// §4.3), written once as a template so that a model can call it with its non-virtual rate
// (the fast path of PerzynaMaterial) while Material::advance_source calls it through the
// virtual interface: classical RK4, sub-stepped against the relaxation rate, where that needs
// few sub-steps; backward Euler (the model's implicit return) beyond, eq. (2.5.6).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "materials/material.hpp"

namespace rktsph::detail {

/// No implicit integrator: RK4 everywhere.
struct NoImplicitSource {};

/// The most pieces backward Euler halves one interval into before the run stops.
inline constexpr long kMaxImplicitPieces = 64;

// Particle i's end state: the source's end stress (additive: plus tau R from the same start).
inline void write_end(const SourceBatch& b, std::size_t i, int ns, int nk, std::size_t kstride, const Sym6& s,
                      const Sym6& r, double tau, bool frozen, const double* k) {
  double* se = b.sigma_end + i * b.sigma_end_stride;
  for (int c = 0; c < ns; ++c) {
    const auto cc = static_cast<std::size_t>(c);
    se[c] = frozen ? s[cc] : s[cc] + tau * r[cc];
  }
  double* k_end = b.state_end + kstride * i;
  for (int j = 0; j < nk; ++j) k_end[j] = k[j];
}

/// rate(sigma, state, dsigma, dstate) is the source rate; relax(sigma, state) its relaxation
/// rate estimate in 1/s; implicit(trial, k0, h, sigma, k) -> ImplicitOutcome the backward-Euler
/// step (or NoImplicitSource). nk is the number of history variables per particle.
template <class RateFn, class RelaxFn, class ImplicitFn = NoImplicitSource>
SourceStats integrate_source_batch(double tau, const SourceBatch& b, int nk, RateFn&& rate, RelaxFn&& relax,
                                   ImplicitFn&& implicit = {}) {
  constexpr bool kHasImplicit = !std::is_same_v<std::remove_cvref_t<ImplicitFn>, NoImplicitSource>;
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
    if (lam == 0.0) {
      // Inside the surface at the start (and, with the frozen flux, at the trial end point, so
      // along the segment between, the surfaces being convex): no flow, the source adds nothing
      // and either coupling ends at s + tau R.
      write_end(b, i, ns, nk, kstride, s, r, tau, false, k);
      ++stats.elastic_points;
      continue;
    }
    const double want = std::ceil(lam * tau / Material::rk4_stability_target);
    if constexpr (kHasImplicit) {
      if (!(want <= static_cast<double>(Material::max_explicit_substeps))) {
        // Backward Euler over tau (eq. 2.5.6); halved into 2, 4, ... pieces while Newton fails.
        const Sym6 s_start = s;
        bool done = false;
        long iterations = 0;
        for (long pieces = 1; pieces <= kMaxImplicitPieces && !done; pieces *= 2) {
          const double h = tau / static_cast<double>(pieces);
          s = s_start;
          for (int j = 0; j < nk; ++j) k[j] = k0[j];
          done = true;
          for (long piece = 0; piece < pieces && done; ++piece) {
            Sym6 trial = s;
            if (frozen) {
              for (std::size_t c = 0; c < 6; ++c) trial[c] += h * r[c];
            }
            double k_end[kMaxState];
            const ImplicitOutcome o = implicit(trial, k, h, s, k_end);
            iterations += o.iterations;
            done = o.converged;
            for (int j = 0; j < nk; ++j) k[j] = k_end[j];
          }
          stats.max_implicit_pieces = std::max(stats.max_implicit_pieces, pieces);
        }
        if (!done) {
          throw SolverError(fmt::format(
              "the implicit viscoplastic return did not converge in {} pieces of the step (stress "
              "[{:.4g}, {:.4g}, {:.4g}, {:.4g}, {:.4g}, {:.4g}] Pa); reduce the time step",
              kMaxImplicitPieces, s_start[0], s_start[1], s_start[2], s_start[3], s_start[4], s_start[5]));
        }
        ++stats.implicit_points;
        stats.newton_iterations += iterations;
        stats.max_newton_iterations = std::max(stats.max_newton_iterations, iterations);
        write_end(b, i, ns, nk, kstride, s, r, tau, frozen, k);
        continue;
      }
    }
    if (!(want <= static_cast<double>(Material::max_substeps))) {
      throw SolverError(
          fmt::format("the viscoplastic source is too stiff: relaxation rate {:.3g} 1/s needs {:.3g} RK4 "
                      "sub-steps per step (limit {}); reduce the fluidity or the time step",
                      lam, want, Material::max_substeps));
    }
    const long substeps = std::max(1L, static_cast<long>(want));
    ++stats.rk4_points;
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
    write_end(b, i, ns, nk, kstride, s, r, tau, frozen, k);
  }
  return stats;
}

}  // namespace rktsph::detail
