// Thesis case 17: saturated vertical cut (docs/cases.md Case 17, V3): the Tresca limit with
// gamma_sat, independent of the permeability. N = 3.4 must stand and N = 4.2 collapse for
// k = 1e-5 and 1e-7 m/s; the crest displacement of the stable runs must not depend much on k;
// the mechanism emerges 0.7H-1.15H behind the crest; the fast gravity ramp is undrained, so at
// its end p_w carries the mean total stress away from the drained faces; no checkerboard in p_w.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "validation/cut_common.hpp"
#include "validation/saturated_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kH = 10.0, kW = 20.0, kRampEnd = 3.0, kHoldEnd = 6.0;

/// Nodal fields of a saturated cut at one time: the cut snapshot plus p_w and the total mean
/// stress p = -tr(sigma' - p_w 1)/3 (compression positive).
struct PwState {
  double time = NAN;
  CutSnapshot cut;
  std::vector<double> pw, p_total;
};

PwState capture(const Simulation<2>& solver) {
  PwState s;
  s.time = solver.time();
  s.cut = snapshot(solver, solver.time());
  const auto n = static_cast<std::size_t>(solver.nodes().size());
  for (std::size_t i = 0; i < n; ++i) {
    const Sym6 sig = solver.node_stress().sym6(i);
    const double pw = solver.node_pore_pressure()[i];
    s.pw.push_back(pw);
    s.p_total.push_back(-(sig[0] + sig[1] + sig[2]) / 3.0 + pw);
  }
  return s;
}

struct SatCut {
  double n_stab = 0.0, k = 0.0;
  CutRun run;
  PwState ramp, hold;                              // at the end of the ramp (3 s) and after 3 s of hold (6 s)
  double uc6 = NAN;                                // crest displacement at t = 6 s
  double pw_lower = NAN, p_lower = NAN;            // end of ramp: means over the lower half away from the drained faces
  double pw_lower_hold = NAN, p_lower_hold = NAN;  // the same at 6 s
  double checker = 0.0, checker_rms = 0.0, checker_scale = 0.0;
  double checker_time = NAN;
};

double sample_at(const std::vector<double>& t, const std::vector<double>& f, double tq) {
  if (t.empty()) return NAN;
  if (tq <= t.front()) return f.front();
  if (tq >= t.back()) return tq - t.back() < 1e-9 ? f.back() : NAN;
  const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), tq) - t.begin());
  const double w = (tq - t[k - 1]) / (t[k] - t[k - 1]);
  return (1.0 - w) * f[k - 1] + w * f[k];
}

SatCut run_saturated_cut(const std::string& file, double dx, double n_stab, double k) {
  SatCut r;
  r.n_stab = n_stab;
  r.k = k;
  const double c = n_stab < 3.78 ? 57710.0 : 46710.0;  // Pa, docs/cases.md Case 17 (gamma_sat H / N)
  const std::vector<std::string> set = {fmt::format("geometry.spacing={}", dx), "output.interval=0",
                                        fmt::format("material.cohesion={:.6g}", c),
                                        fmt::format("fluid.conductivity={:g}", k)};
  r.run = run_cut(file, set, 0.01, 0.1, [&](const Simulation<2>& s) {
    const double h = 0.5 * s.dt();
    if (std::isnan(r.ramp.time) && s.time() >= kRampEnd - h) r.ramp = capture(s);
    if (std::isnan(r.hold.time) && s.time() >= kHoldEnd - h) r.hold = capture(s);
  });
  r.uc6 = sample_at(r.run.t, r.run.uc, kHoldEnd);
  // End of the ramp: mean p_w and mean total stress over the lower half (y <= H/2), at least
  // H/2 from the drained face (the drained top is at least H/2 away there).
  auto lower_means = [&](const PwState& s, double& pw, double& pt) {
    if (std::isnan(s.time)) return;
    double sp = 0.0, st = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < s.pw.size(); ++i) {
      if (s.cut.y[i] > 0.5 * kH + 1e-9 || s.cut.x[i] > kW - 0.5 * kH + 1e-9) continue;
      sp += s.pw[i];
      st += s.p_total[i];
      ++n;
    }
    pw = sp / n;
    pt = st / n;
  };
  lower_means(r.ramp, r.pw_lower, r.p_lower);
  lower_means(r.hold, r.pw_lower_hold, r.p_lower_hold);
  // Checkerboard at both captured times; drained nodes (top row, face column) left out.
  for (const PwState* s : {&r.ramp, &r.hold}) {
    if (std::isnan(s->time)) continue;
    std::vector<bool> drained(s->pw.size());
    double scale = 0.0;
    for (std::size_t i = 0; i < s->pw.size(); ++i) {
      drained[i] = std::abs(s->cut.y[i] - kH) < 1e-6 * dx || std::abs(s->cut.x[i] - kW) < 1e-6 * dx;
      scale = std::max(scale, std::abs(s->pw[i]));
    }
    double rms = 0.0;
    const double a = checkerboard_amplitude(s->cut.x, s->cut.y, s->pw, dx, &rms, &drained);
    if (scale > 0.0 && (r.checker_scale == 0.0 || a / scale >= r.checker / r.checker_scale)) {
      r.checker = a;
      r.checker_rms = rms;
      r.checker_scale = scale;
      r.checker_time = s->time;
    }
  }
  return r;
}

std::string label(const SatCut& r) { return fmt::format("N{}_k{:g}", r.n_stab, r.k); }

void write_state(const std::string& file, const PwState& s) {
  std::ofstream f(file);
  f << "x,y,ux,uy,vx,vy,eps_vp_eq,pw,p_total\n";
  for (std::size_t i = 0; i < s.pw.size(); ++i) {
    f << fmt::format("{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", s.cut.x[i], s.cut.y[i],
                     s.cut.ux[i], s.cut.uy[i], s.cut.vx[i], s.cut.vy[i], s.cut.eps[i], s.pw[i], s.p_total[i]);
  }
}

}  // namespace

CaseReport validate_case17(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "17";
  rep.title = "Saturated vertical cut (V3)";
  rep.reference =
      "docs/cases.md Case 17: limit analysis of a vertical cut in a Tresca material with gamma_sat, N_c = "
      "gamma_sat H/c ~ 3.78 (bracket 2.83-4.00), independent of k; circular mechanism emerging 0.91H behind "
      "the crest; undrained ramp: p_w = mean total stress";
  const std::string file = (fs::path(opt.cases_dir) / "17_saturated_vertical_cut_2d.toml").string();
  const double dx = opt.full ? 0.25 : 0.5;
  std::vector<SatCut> runs;
  for (double n : {3.4, 4.2}) {
    for (double k : {1e-5, 1e-7}) runs.push_back(run_saturated_cut(file, dx, n, k));
  }
  const std::string tag = fmt::format("dx = {} m: ", dx);
  for (const SatCut& r : runs) {
    const std::string rt = tag + fmt::format("N = {}, k = {:g} m/s: ", r.n_stab, r.k);
    const CutOutcome expected = r.n_stab < 3.78 ? CutOutcome::stable : CutOutcome::collapse;
    rep.metrics.push_back(outcome_metric(rt + "classified " + outcome_name(expected), r.run, expected));
    rep.notes.push_back(run_note(fmt::format("N = {}, k = {:g} m/s", r.n_stab, r.k), r.run));
    write_history_csv((fs::path(dir) / fmt::format("history_{}.csv", label(r))).string(), r.run);
    if (!std::isnan(r.ramp.time)) write_state((fs::path(dir) / fmt::format("ramp_{}.csv", label(r))).string(), r.ramp);
    if (!std::isnan(r.hold.time)) write_state((fs::path(dir) / fmt::format("hold_{}.csv", label(r))).string(), r.hold);
    write_snapshot_csv((fs::path(dir) / fmt::format("final_{}.csv", label(r))).string(), r.run.final_state);
  }
  // Crest displacement at 6 s of the stable runs, between the permeabilities.
  {
    const double a = runs[0].uc6, b = runs[1].uc6;
    rep.metrics.push_back(metric(tag + "N = 3.4: |u_c(6 s, k = 1e-5) - u_c(6 s, k = 1e-7)| / their mean",
                                 std::abs(a - b) / (0.5 * (std::abs(a) + std::abs(b))), "<=", 0.20, ""));
    rep.notes.push_back(
        fmt::format("N = 3.4: u_c(6 s) = {:.4e} m (k = 1e-5 m/s), {:.4e} m (k = 1e-7 m/s); N = 4.2: "
                    "{:.4e} m, {:.4e} m",
                    a, b, runs[2].uc6, runs[3].uc6));
  }
  // Mechanism of the collapse runs.
  std::string emergence_csv = "label,emergence,toe_distance\n";
  for (std::size_t j = 2; j < 4; ++j) {
    const SatCut& r = runs[j];
    const std::string rt = tag + fmt::format("N = 4.2, k = {:g} m/s: ", r.k);
    const double emerge = emergence_behind_crest(r.run.final_state, dx, kW, kH);
    const double toe = band_distance_to(r.run.final_state, kW, 0.0, 0.0);
    rep.metrics.push_back(metric(rt + "emergence on the top behind the crest, >= 0.7 H", emerge, ">=", 0.7 * kH, "m"));
    rep.metrics.push_back(
        metric(rt + "emergence on the top behind the crest, <= 1.15 H", emerge, "<=", 1.15 * kH, "m"));
    rep.metrics.push_back(
        metric(rt + "distance of the failure surface (eps_vp_eq >= 50 % of max) from the toe", toe, "", 0, "m"));
    emergence_csv += fmt::format("{},{},{}\n", label(r), emerge, toe);
  }
  std::ofstream(fs::path(dir) / "meta.csv") << fmt::format("dx,H,W\n{},{},{}\n", dx, kH, kW);
  std::ofstream(fs::path(dir) / "emergence.csv") << emergence_csv;
  // Undrained ramp and checkerboard.
  for (const SatCut& r : runs) {
    const std::string rt = tag + fmt::format("N = {}, k = {:g} m/s: ", r.n_stab, r.k);
    rep.metrics.push_back(metric(rt + "end of ramp, |mean p_w / mean total stress - 1| (y <= H/2, x <= W - H/2)",
                                 std::abs(r.pw_lower / r.p_lower - 1.0), "<=", 0.15, ""));
    rep.metrics.push_back(metric(rt + "checkerboard: max alternating p_w component / max |p_w| (3 s and 6 s)",
                                 r.checker_scale > 0.0 ? r.checker / r.checker_scale : NAN, "<=", 0.01, ""));
    rep.metrics.push_back(metric(rt + "change of mean p_w over the hold 3 -> 6 s / its value at 3 s (same region; "
                                      "physically ~0: drainage reaches about sqrt(c_v t) < 1 m in 6 s)",
                                 r.pw_lower_hold / r.pw_lower - 1.0, "", 0, ""));
    rep.notes.push_back(
        fmt::format("N = {}, k = {:g} m/s: end of ramp (t = {:.3f} s) mean p_w = {:.1f} kPa, mean total "
                    "stress {:.1f} kPa over y <= H/2, x <= W - H/2; p_w checkerboard max {:.3g} kPa, rms "
                    "{:.3g} kPa (at t = {:.2f} s, max |p_w| {:.1f} kPa)",
                    r.n_stab, r.k, r.ramp.time, r.pw_lower / 1e3, r.p_lower / 1e3, r.checker / 1e3, r.checker_rms / 1e3,
                    r.checker_time, r.checker_scale / 1e3));
  }
  rep.notes.push_back(
      "checkerboard measure: the fourth difference |f_(i-2) - 4 f_(i-1) + 6 f_i - 4 f_(i+1) + f_(i+2)|/16 "
      "along x and y (exact amplitude of a node-to-node alternation, zero for any cubic field) over the "
      "non-drained nodes, divided by max |p_w|");
  if (!opt.full) rep.notes.push_back("quick mode: dx = 0.5 m; --full runs docs/cases.md's 0.25 m");
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case17.py", dir, note)) {
      for (const char* p : {"case17/histories.png", "case17/pw_maps.png", "case17/eps_maps.png"})
        rep.plots.push_back(p);
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
