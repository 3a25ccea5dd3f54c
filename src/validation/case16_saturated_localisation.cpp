// Thesis case 16: strain localisation in a saturated Cam-Clay sample (docs/cases.md Case 16, V3):
// the undrained elastic stage and first yield against their closed forms, the undrained
// critical-state end point (k = 1e-9 m/s, no band), and the band with water drawn into it
// (k = 1e-6 m/s). The sample, platens and material are those of case 3.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "validation/band_common.hpp"
#include "validation/saturated_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

// docs/cases.md Case 16 (case-3 material and loading, saturated).
constexpr double kE = 2.0e7, kNu = 0.3, kM = 1.2, kP0 = 5.0e4, kPc0 = 4.0e5;
constexpr double kLambda = 0.20, kKappa = 0.02, kE0 = 1.0;
constexpr double kPorosity = 0.4, kKf = 2.2e9;
constexpr double kHeight = kSampleHeight, kWidth = kSampleWidth;
// First yield is taken where the volume-averaged eps_vp_eq first reaches this value (1.7 % of
// the first-yield axial strain): the sample's response leaves the elastic path there.
constexpr double kYieldEps = 1.0e-4;

/// Closed forms of docs/cases.md Case 16. Elasticity of our Cam-Clay is constant E and nu
/// (src/materials, docs/materials.md), so the constant-K end point of docs/cases.md applies.
/// s = sigma_1 - sigma_3 (total, compression positive); the lateral total stress is constant.
struct Undrained {
  double K = kE / (3.0 * (1.0 - 2.0 * kNu));
  double G = kE / (2.0 * (1.0 + kNu));
  double Q = kKf / kPorosity;
  double B = Q / (K + Q);
  double Ku = K + Q;
  double nu_u = (3.0 * Ku - 2.0 * G) / (2.0 * (3.0 * Ku + G));
  double Eu = 2.0 * G * (1.0 + nu_u);
  double root = std::sqrt(1.0 - nu_u + nu_u * nu_u);
  double q(double s) const { return s * root; }
  double dpw(double s) const { return B * (1.0 + nu_u) * s / 3.0; }
  double p(double s) const { return kP0 + (1.0 - B) * (1.0 + nu_u) * s / 3.0; }
  double strain(double s) const { return (1.0 - nu_u * nu_u) * s / Eu; }
  double s_of_strain(double e) const { return Eu * e / (1.0 - nu_u * nu_u); }
  /// First yield: q^2/M^2 + p'(p' - p_c0) = 0 along the undrained elastic path.
  double yield_s() const {
    const double A = root * root / (kM * kM), b1 = (1.0 - B) * (1.0 + nu_u) / 3.0;
    const double a = A + b1 * b1, b = b1 * (2.0 * kP0 - kPc0), c = kP0 * (kP0 - kPc0);
    return (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
  }
  /// Undrained critical state (isochoric, constant K): p_c0 exp[-v0 (p' - p0')/((lambda - kappa) K)] = 2 p'.
  double critical_p() const {
    auto f = [&](double p) { return kPc0 * std::exp(-(1.0 + kE0) * (p - kP0) / ((kLambda - kKappa) * K)) - 2.0 * p; };
    double lo = kP0, hi = 0.5 * kPc0;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (f(mid) > 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

struct Snapshot {
  double strain = 0.0;
  std::vector<double> x, y, eps, pw, q, vx, vy;
};

struct SatRun {
  double dx = 0.0, k = 0.0;
  std::vector<double> strain, q, p, dpw, eps_mean, eps_cov;  // histories (volume averages; CoV of eps_vp_eq)
  double elastic_q_err = 0.0, elastic_pw_err = 0.0;          // max relative error, 0.3-0.9 eps_a,y
  int elastic_samples = 0;
  double q_half = NAN, pw_half = NAN;                           // at eps_a = 0.5 eps_a,y
  double fy_q = NAN, fy_p = NAN, fy_pw = NAN, fy_strain = NAN;  // first yield
  double q_end = 0.0, p_end = 0.0, pw_end = 0.0, strain_end = 0.0;
  double q_peak = 0.0, strain_peak = 0.0, cov_at_peak = NAN;
  double cov_eps = NAN, cov_eps_interior = NAN;                  // at the end, all nodes / 0.1 m off the platens
  double checker = 0.0, checker_rms = 0.0, checker_scale = 0.0;  // largest over the snapshots, Pa
  // The same over the stencils that do not touch the seed (the imperfection's nodes), relative
  // to max |p_w|: a genuine pressure contrast at the seed's edge, two dx wide, has a large fourth
  // difference too.
  double checker_off_seed = 0.0;
  std::vector<Snapshot> snaps;
  // The band of docs/cases.md §1.3, the imperfection outside the band region (its nodes in
  // neither the threshold's maximum nor the cloud), and the same fit with it (the measure
  // before December 2026, reported).
  BandFit band, band_with_seed;
  double pw_band = NAN, pw_around = NAN;  // mean p_w in the band / in the zone around it
  int around_count = 0;
  double pw_seed_band = NAN, pw_seed_around = NAN;  // the same for the cloud with the imperfection
  long steps = 0, max_substeps = 0, iterations_max = 0;
  double iterations_mean = 0.0, residual = 0.0, pressure_share = 0.0, seconds = 0.0;
};

std::string label(double k) { return fmt::format("k{:g}", k); }

SatRun run_sample(const std::string& case_file, double dx, double k, double end_strain,
                  const std::vector<double>& snap_strains, const Undrained& u) {
  const double s_y = u.yield_s(), eps_y = u.strain(s_y);
  const double t_end = platen_time(end_strain);
  std::vector<std::string> set = {fmt::format("geometry.spacing={}", dx), fmt::format("time.end={}", t_end),
                                  fmt::format("fluid.conductivity={:g}", k), "output.interval=0"};
  if (std::abs(std::remainder(0.5 * kWidth, dx)) > 1e-9) {  // no node at x = 0.5 m: pin the nearest
    const double xc = std::floor(0.5 * kWidth / dx) * dx;
    set.push_back(fmt::format("boundary.1.x=[{},{}]", xc, xc));
  }
  const CaseDocument doc = load_case_document(case_file, set);
  CaseSetup<2> setup = read_case<2>(doc);
  Simulation<2> solver(setup);
  pressure_stage(solver, "case 16");  // throws for a dry case
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  const HistoryView eps_of = node_history(solver, "eps_vp_eq", "case 16");
  const std::vector<char> seed = imperfection_nodes(solver);
  const std::vector<bool> seed_skip(seed.begin(), seed.end());
  auto q_of = [&](std::size_t i) { return solver.node_stress().invariants(i).q; };
  double volume = 0.0;
  for (std::size_t i = 0; i < nn; ++i) volume += nodes.volume[i];

  SatRun out;
  out.dx = dx;
  out.k = k;
  const long steps = static_cast<long>(std::ceil(t_end / solver.dt()));
  const long record_every = std::max(1L, steps / 2000);
  std::size_t next_snap = 0;
  bool half_done = false;
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n <= steps; ++n) {
    if (n > 0) solver.step();
    const double strain = platen_strain(solver.time());
    const bool snap_due = next_snap < snap_strains.size() && strain >= snap_strains[next_snap] - 1e-12;
    const bool yield_pending = std::isnan(out.fy_q);
    if (n % record_every != 0 && n != steps && !snap_due && !yield_pending) continue;
    // Volume averages of the nodal effective stress, p_w and eps_vp_eq; q and p' of the
    // averaged effective stress (q is the same for the total stress).
    Sym6 avg{};
    double eps_mean = 0.0, eps_sq = 0.0, pw_mean = 0.0;
    for (std::size_t i = 0; i < nn; ++i) {
      const Sym6 s = solver.node_stress().sym6(i);
      const double w = nodes.volume[i] / volume;
      for (std::size_t c = 0; c < 6; ++c) avg[c] += w * s[c];
      const double e = eps_of(i);
      eps_mean += w * e;
      eps_sq += w * e * e;
      pw_mean += w * solver.node_pore_pressure()[i];
    }
    const double eps_cov = eps_mean > 0.0 ? std::sqrt(std::max(0.0, eps_sq - eps_mean * eps_mean)) / eps_mean : 0.0;
    const Invariants inv = invariants(avg);
    if (yield_pending && eps_mean >= kYieldEps) {
      out.fy_q = inv.q;
      out.fy_p = inv.p;
      out.fy_pw = pw_mean;
      out.fy_strain = strain;
    }
    if (n % record_every == 0 || n == steps) {
      out.strain.push_back(strain);
      out.q.push_back(inv.q);
      out.p.push_back(inv.p);
      out.dpw.push_back(pw_mean);
      out.eps_mean.push_back(eps_mean);
      out.eps_cov.push_back(eps_cov);
      if (strain >= 0.3 * eps_y && strain <= 0.9 * eps_y) {
        const double s = u.s_of_strain(strain);
        out.elastic_q_err = std::max(out.elastic_q_err, std::abs(inv.q / u.q(s) - 1.0));
        out.elastic_pw_err = std::max(out.elastic_pw_err, std::abs(pw_mean / u.dpw(s) - 1.0));
        ++out.elastic_samples;
        if (!half_done && strain >= 0.5 * eps_y) {
          out.q_half = inv.q;
          out.pw_half = pw_mean;
          half_done = true;
        }
      }
      if (inv.q > out.q_peak) {
        out.q_peak = inv.q;
        out.strain_peak = strain;
        out.cov_at_peak = eps_cov;
      }
    }
    out.q_end = inv.q;
    out.p_end = inv.p;
    out.pw_end = pw_mean;
    out.strain_end = strain;
    while (next_snap < snap_strains.size() && strain >= snap_strains[next_snap] - 1e-12) {
      Snapshot s;
      s.strain = strain;
      for (std::size_t i = 0; i < nn; ++i) {
        s.x.push_back(nodes.position[i][0]);
        s.y.push_back(nodes.position[i][1]);
        s.eps.push_back(eps_of(i));
        s.pw.push_back(solver.node_pore_pressure()[i]);
        s.q.push_back(q_of(i));
        s.vx.push_back(solver.node_velocity()(i, 0));
        s.vy.push_back(solver.node_velocity()(i, 1));
      }
      double rms = 0.0, scale = 0.0;
      const double c = checkerboard_amplitude(s.x, s.y, s.pw, dx, &rms);
      for (double p : s.pw) scale = std::max(scale, std::abs(p));
      if (scale > 0.0 && (out.checker_scale == 0.0 || c / scale >= out.checker / out.checker_scale)) {
        out.checker = c;
        out.checker_rms = rms;
        out.checker_scale = scale;
      }
      if (scale > 0.0) {
        out.checker_off_seed =
            std::max(out.checker_off_seed, checkerboard_amplitude(s.x, s.y, s.pw, dx, nullptr, &seed_skip) / scale);
      }
      out.snaps.push_back(std::move(s));
      ++next_snap;
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!out.snaps.empty()) {
    const Snapshot& s = out.snaps.back();
    // Coefficient of variation of eps_vp_eq over the nodes (volume weighted): all nodes, and
    // the nodes more than 0.1 m from the platens.
    auto cov = [&](double margin) {
      double w = 0.0, m = 0.0, m2 = 0.0;
      for (std::size_t i = 0; i < nn; ++i) {
        if (s.y[i] < margin - 1e-9 || s.y[i] > kHeight - margin + 1e-9) continue;
        w += nodes.volume[i];
        m += nodes.volume[i] * s.eps[i];
        m2 += nodes.volume[i] * s.eps[i] * s.eps[i];
      }
      m /= w;
      return std::sqrt(std::max(0.0, m2 / w - m * m)) / m;
    };
    out.cov_eps = cov(0.0);
    out.cov_eps_interior = cov(0.1 + 1e-9);
    out.band = fit_band(s.x, s.y, s.eps, kHeight, 0.1, 0.04, 1.0, seed);
    out.band_with_seed = fit_band(s.x, s.y, s.eps, kHeight, 0.1, 0.04, 1.0);
    // p_w in the band cloud against the zone around it: the nodes outside the cloud within
    // 0.2 m (about twice the band width of docs/cases.md) of a cloud node, off the platen margins
    // (and off the imperfection for the band of the criterion).
    for (const bool with_seed : {false, true}) {
      const BandFit& band = with_seed ? out.band_with_seed : out.band;
      double sb = 0.0, sa = 0.0;
      int nb = 0, na = 0;
      std::vector<std::size_t> cloud;
      for (std::size_t i = 0; i < nn; ++i) {
        if (band.in_band[i]) cloud.push_back(i);
      }
      for (std::size_t i = 0; i < nn; ++i) {
        if (!with_seed && seed[i]) continue;
        if (band.in_band[i]) {
          sb += s.pw[i];
          ++nb;
          continue;
        }
        if (s.y[i] <= 0.1 || s.y[i] >= kHeight - 0.1) continue;
        for (std::size_t j : cloud) {
          if (std::hypot(s.x[i] - s.x[j], s.y[i] - s.y[j]) <= 0.2 + 1e-9) {
            sa += s.pw[i];
            ++na;
            break;
          }
        }
      }
      (with_seed ? out.pw_seed_band : out.pw_band) = nb > 0 ? sb / nb : NAN;
      (with_seed ? out.pw_seed_around : out.pw_around) = na > 0 ? sa / na : NAN;
      if (!with_seed) out.around_count = na;
    }
  }
  out.steps = solver.step_count();
  out.max_substeps = solver.max_source_substeps();
  if (const PressureSolveStats* ps = &pressure_stage(solver, "case 16").stats(); ps != nullptr) {  // V3: always set
    out.iterations_max = ps->max_iterations;
    out.iterations_mean = ps->mean_iterations();
    out.residual = ps->max_error;
  }
  out.pressure_share = pressure_stage(solver, "case 16").seconds() / out.seconds;
  return out;
}

void write_run(const std::string& dir, const SatRun& r) {
  {
    std::ofstream f(fmt::format("{}/history_{}.csv", dir, label(r.k)));
    f << "strain,q,p,dpw,eps_vp_eq_mean,eps_vp_eq_cov\n";
    for (std::size_t k = 0; k < r.strain.size(); ++k) {
      f << fmt::format("{:.8g},{:.10g},{:.10g},{:.10g},{:.8g},{:.6g}\n", r.strain[k], r.q[k], r.p[k], r.dpw[k],
                       r.eps_mean[k], r.eps_cov[k]);
    }
  }
  std::ofstream f(fmt::format("{}/snapshots_{}.csv", dir, label(r.k)));
  f << "strain,x,y,eps_vp_eq,pw,q,vx,vy,in_band\n";
  for (std::size_t n = 0; n < r.snaps.size(); ++n) {
    const Snapshot& s = r.snaps[n];
    const bool last = n + 1 == r.snaps.size();
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      f << fmt::format("{:.6g},{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{}\n", s.strain, s.x[i], s.y[i],
                       s.eps[i], s.pw[i], s.q[i], s.vx[i], s.vy[i],
                       last && !r.band.in_band.empty() ? int(r.band.in_band[i]) : 0);
    }
  }
}

}  // namespace

CaseReport validate_case16(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "16";
  rep.title = "Saturated Cam-Clay plane-strain compression, strain localisation (V3)";
  rep.reference =
      "closed forms of docs/cases.md Case 16 (constant M, constant E and nu): undrained elastic stage "
      "dp_w = B(1+nu_u)s/3 and q = s sqrt(1-nu_u+nu_u^2), first yield q_y = 159.1 kPa, undrained "
      "critical state p'_f = 183.0 kPa, q_f = 219.6 kPa; band-angle bounds 43-68 deg";
  const std::string case_file = (fs::path(opt.cases_dir) / "16_saturated_cam_clay_localisation_2d.toml").string();
  const Undrained u;
  const double s_y = u.yield_s();
  const double q_y = u.q(s_y), pw_y = u.dpw(s_y), eps_y = u.strain(s_y);
  const double p_f = u.critical_p(), q_f = kM * p_f;
  {
    std::ofstream f(fs::path(dir) / "closed_form.csv");
    f << "strain,q,p,dpw\n";
    for (int k = 0; k <= 50; ++k) {
      const double s = s_y * k / 50.0;
      f << fmt::format("{:.8g},{:.10g},{:.10g},{:.10g}\n", u.strain(s), u.q(s), u.p(s), u.dpw(s));
    }
    std::ofstream m(fs::path(dir) / "meta.csv");
    m << "q_y,p_y,dpw_y,eps_y,p_f,q_f\n"
      << fmt::format("{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", q_y, u.p(s_y), pw_y, eps_y, p_f, q_f);
  }
  rep.notes.push_back(fmt::format(
      "closed form: B = {:.4f}, nu_u = {:.4f}, E_u = {:.2f} MPa; first yield s = {:.1f} kPa, q_y = {:.1f} kPa, p'_y = "
      "{:.1f} kPa, dp_w = {:.1f} kPa, eps_a = {:.3f} %; undrained critical state p'_f = {:.1f} kPa, q_f = {:.1f} kPa "
      "(constant-K elasticity: our Cam-Clay has constant E and nu, docs/materials.md)",
      u.B, u.nu_u, u.Eu / 1e6, s_y / 1e3, q_y / 1e3, u.p(s_y) / 1e3, pw_y / 1e3, 100 * eps_y, p_f / 1e3, q_f / 1e3));

  // --quick: dx = 0.04 m (25 x 50); --full: docs/cases.md's dx = 0.02 m. Both run to 8 %.
  const double dx = opt.full ? 0.02 : 0.04;
  const std::vector<double> snaps = {0.03, 0.05, 0.08};
  const SatRun und = run_sample(case_file, dx, 1e-9, 0.08, snaps, u);
  const SatRun loc = run_sample(case_file, dx, 1e-6, 0.08, snaps, u);
  write_run(dir, und);
  write_run(dir, loc);
  std::ofstream(fs::path(dir) / "plot_input.txt") << fmt::format("{}\n", dx);

  for (const SatRun* r : {&und, &loc}) {
    const std::string tag = fmt::format("k = {:g} m/s: ", r->k);
    rep.metrics.push_back(metric(tag + "elastic stage, max |q / closed form - 1| over 0.3-0.9 eps_a,y",
                                 r->elastic_q_err, "<=", 0.03, ""));
    rep.metrics.push_back(metric(tag + "elastic stage, max |mean dp_w / closed form - 1| over 0.3-0.9 eps_a,y",
                                 r->elastic_pw_err, "<=", 0.03, ""));
    const double dq = r->fy_q / q_y - 1.0;
    rep.metrics.push_back(
        metric(tag + fmt::format("first yield (mean eps_vp_eq = {:g}): q / q_y - 1 (upper +4 %)", kYieldEps), dq,
               "<=", 0.04, ""));
    rep.metrics.push_back(metric(tag + "first yield: q / q_y - 1 (lower +0 %)", dq, ">=", 0.0, ""));
    rep.metrics.push_back(metric(tag + "checkerboard: max alternating p_w component / max |p_w| (snapshots 3, 5, 8 %)",
                                 r->checker_scale > 0.0 ? r->checker / r->checker_scale : NAN, "<=", 0.01, ""));
    rep.metrics.push_back(metric(tag + "checkerboard over the stencils that do not touch the imperfection",
                                 r->checker_off_seed, "", 0.0, ""));
    rep.notes.push_back(fmt::format(
        "k = {:g} m/s, dx = {} m: at eps_a = 0.5 eps_a,y q = {:.2f} kPa (closed form {:.2f}), mean dp_w = {:.2f} kPa "
        "({:.2f}); first yield at eps_a = {:.3f} % (closed form {:.3f} %), q = {:.1f} kPa, p' = {:.1f} kPa, dp_w = "
        "{:.1f} "
        "kPa (closed form {:.1f}); at {:.1f} %: q = {:.1f} kPa, p' = {:.1f} kPa, mean p_w = {:.1f} kPa; peak q {:.1f} "
        "kPa "
        "at {:.2f} %; CoV of eps_vp_eq {:.3f} (all nodes), {:.3f} (0.1 m off the platens); p_w checkerboard max {:.3g} "
        "kPa, rms {:.3g} kPa, max |p_w| {:.1f} kPa; {} steps, RK4 sub-steps max {}, PCG (Jacobi) iterations mean "
        "{:.1f}, "
        "max {}, max residual {:.1e}; pressure step {:.0f} % of {:.0f} s",
        r->k, r->dx, r->q_half / 1e3, u.q(u.s_of_strain(0.5 * eps_y)) / 1e3, r->pw_half / 1e3,
        u.dpw(u.s_of_strain(0.5 * eps_y)) / 1e3, 100 * r->fy_strain, 100 * eps_y, r->fy_q / 1e3, r->fy_p / 1e3,
        r->fy_pw / 1e3, pw_y / 1e3, 100 * r->strain_end, r->q_end / 1e3, r->p_end / 1e3, r->pw_end / 1e3,
        r->q_peak / 1e3, 100 * r->strain_peak, r->cov_eps, r->cov_eps_interior, r->checker / 1e3, r->checker_rms / 1e3,
        r->checker_scale / 1e3, r->steps, r->max_substeps, r->iterations_mean, r->iterations_max, r->residual,
        100 * r->pressure_share, r->seconds));
  }
  // ---- k = 1e-9: homogeneous undrained response to the critical state, no band
  const std::string te = fmt::format("at {:.0f} %", 100 * und.strain_end);
  rep.metrics.push_back(metric("k = 1e-9 m/s: |p' " + te + " / p'_f - 1| (p'_f = 183.0 kPa)",
                               std::abs(und.p_end / p_f - 1.0), "<=", 0.05, ""));
  rep.metrics.push_back(metric("k = 1e-9 m/s: |q " + te + " / q_f - 1| (q_f = 219.6 kPa)",
                               std::abs(und.q_end / q_f - 1.0), "<=", 0.05, ""));
  rep.metrics.push_back(metric("k = 1e-9 m/s: p' " + te, und.p_end / 1e3, "", 0, "kPa"));
  rep.metrics.push_back(metric("k = 1e-9 m/s: q " + te, und.q_end / 1e3, "", 0, "kPa"));
  {
    Metric m = metric("k = 1e-9 m/s: coefficient of variation of eps_vp_eq " + te + " (all nodes)", und.cov_eps,
                      "<=", 0.20, "");
    if (!m.pass()) {
      m.known_deviation =
          "the 'undrained' sample forms a conjugate pair of bands from the imperfection. The law has no undrained "
          "hardening left past its peak (at one material point, same path and rate: q peaks at 221.9 kPa at 2.2 % "
          "and softens to q_f), so the weaker seed localises the strain; without the imperfection the same run stays "
          "homogeneous (CoV 0.014 at 8 %, dx = 0.04 m). The wall leak of the old non-incremental projection, "
          "suspected before, is ruled out: the leak-free defaults give the same CoV (docs/VALIDATION.md, Case 16)";
    }
    rep.metrics.push_back(m);
  }
  rep.metrics.push_back(metric("k = 1e-9 m/s: coefficient of variation of eps_vp_eq, 0.1 m off the platens",
                               und.cov_eps_interior, "", 0, ""));
  rep.metrics.push_back(
      metric(fmt::format("k = 1e-9 m/s: coefficient of variation of eps_vp_eq at the peak of q ({:.2f} %)",
                         100 * und.strain_peak),
             und.cov_at_peak, "", 0, ""));
  // ---- k = 1e-6: a band, with lower p_w inside
  for (const bool lower : {true, false}) {
    Metric m =
        metric("k = 1e-6 m/s: band angle to the horizontal " + te + (lower ? " (lower bound)" : " (upper bound)"),
               loc.band.angle, lower ? ">=" : "<=", lower ? 43.0 : 68.0, "deg");
    if (!m.pass() && loc.band.particles < 30) {
      m.known_deviation = fmt::format(
          "the cloud above 50 % of the largest eps_vp_eq outside the imperfection is {} particles, the "
          "imperfection's rim: at this resolution the bands (a conjugate pair from the imperfection, see the maps) "
          "have not yet formed away from it, so docs/cases.md §1.3's threshold does not see them",
          loc.band.particles);
    }
    rep.metrics.push_back(m);
  }
  rep.metrics.push_back(metric(fmt::format("k = 1e-6 m/s: band angle with the imperfection inside the band region "
                                           "(the measure before December 2026; {} particles)",
                                           loc.band_with_seed.particles),
                               loc.band_with_seed.angle, "", 0, "deg"));
  rep.metrics.push_back(metric("k = 1e-6 m/s: band upper arm angle", loc.band.upper, "", 0, "deg"));
  rep.metrics.push_back(metric("k = 1e-6 m/s: band lower arm angle", loc.band.lower, "", 0, "deg"));
  rep.metrics.push_back(metric("k = 1e-6 m/s: whole-cloud principal axis angle", loc.band.whole, "", 0, "deg"));
  rep.metrics.push_back(
      metric("k = 1e-6 m/s: particles in the band (eps >= 50 % of the largest outside the "
             "imperfection)",
             loc.band.particles, "", 0, ""));
  rep.metrics.push_back(
      metric("k = 1e-6 m/s: coefficient of variation of eps_vp_eq " + te + " (all nodes)", loc.cov_eps, "", 0, ""));
  {
    Metric m = metric("k = 1e-6 m/s: mean p_w in the band - mean p_w within 0.2 m around it (must be < 0)",
                      (loc.pw_band - loc.pw_around) / 1e3, "<=", 0.0, "kPa");
    if (!m.pass()) {
      m.known_deviation = fmt::format(
          "p_w is higher in the band than around it, with the imperfection in the cloud too ({:+.2f} kPa), and about "
          "as much in the practically undrained k = 1e-9 run ({:+.2f} kPa): the contrast is the undrained one. "
          "Drainage moves it the expected way (k = 1e-6 minus k = 1e-9: {:+.2f} kPa) but over the run's 1.6 s it "
          "reaches sqrt(c_v t) ~ 0.07 m, a few dx, too little to reverse it",
          (loc.pw_seed_band - loc.pw_seed_around) / 1e3, (und.pw_band - und.pw_around) / 1e3,
          (loc.pw_band - loc.pw_around - (und.pw_band - und.pw_around)) / 1e3);
    }
    rep.metrics.push_back(m);
  }
  rep.metrics.push_back(
      metric("k = 1e-6 m/s: mean p_w in the cloud with the imperfection - within 0.2 m around it (former measure)",
             (loc.pw_seed_band - loc.pw_seed_around) / 1e3, "", 0, "kPa"));
  rep.notes.push_back(fmt::format(
      "k = 1e-6 m/s band {}: {} particles, angle {:.1f} deg (arms {:.1f} / {:.1f}, whole cloud {:.1f}), axis {:.3f} m "
      "from the imperfection centre; mean p_w {:.2f} kPa in the band, {:.2f} kPa in the {} nodes around it",
      loc.band.pair ? "(conjugate pair, angle = mean of the arms)"
                    : "(single band, angle = principal axis of the cloud)",
      loc.band.particles, loc.band.angle, loc.band.upper, loc.band.lower, loc.band.whole, loc.band.offset,
      loc.pw_band / 1e3, loc.pw_around / 1e3, loc.around_count));
  if (loc.band.particles < 30) {
    rep.notes.push_back(
        fmt::format("k = 1e-6 m/s: the cloud above 50 % of the largest eps_vp_eq outside the imperfection has "
                    "only {} particles: it is the imperfection's rim, not a developed band, so the band angle and "
                    "the p_w comparison refer to that zone; read the maps",
                    loc.band.particles));
  }
  rep.notes.push_back(fmt::format(
      "k = 1e-9 m/s band fit for comparison: {} particles, angle {:.1f} deg; mean p_w in that cloud {:.2f} kPa, around "
      "it {:.2f} kPa",
      und.band.particles, und.band.angle, und.pw_band / 1e3, und.pw_around / 1e3));
  rep.notes.push_back(
      "checkerboard measure: the fourth difference |f_(i-2) - 4 f_(i-1) + 6 f_i - 4 f_(i+1) + f_(i+2)|/16 "
      "along x and y (exact amplitude of a node-to-node alternation, zero for any cubic field), largest "
      "over the nodes whose stencils fit in the sample, divided by max |p_w|");
  if (!opt.full) rep.notes.push_back("quick mode: dx = 0.04 m; --full runs docs/cases.md's 0.02 m");
  std::string note;
  if (opt.plots && run_plot_script("plot_case16.py", dir, note)) {
    rep.plots = {"case16/response.png", "case16/maps.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
