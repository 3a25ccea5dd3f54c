// Thesis case 1: 1D elastic bar, test of stability (docs/cases.md Case 1, revised acceptance).
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "validation/analytic.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kL = 10.0, kE = 1.0e7, kRho = 2000.0, kSigma0 = 1.0e4;
const double kC = std::sqrt(kE / kRho);
const double kTransit = kL / kC;  // L/c, s

struct BarRun {
  int n = 0;
  double cfl = 0.0;
  double sign = 1.0;
  bool smooth = false;
  bool collocated = false;
  double end = 0.0;
};

struct BarResult {
  std::vector<double> snapshot_times;                // in units of L/c, as requested
  std::vector<double> snapshot_e1;                   // L1 relative error of sigma at each snapshot
  std::vector<std::vector<double>> x, sigma, exact;  // profiles at each snapshot
  double max_abs_stress = 0.0;                       // over all steps and nodes, / |sigma0|
  double max_zigzag = 0.0;                           // RMS second difference away from fronts, / |sigma0|
  double zigzag_early = 0.0;                         // its maximum over the first 5 L/c
  double zigzag_late = 0.0;                          // its maximum over the last 5 L/c
  double max_energy_error = 0.0;                     // |imbalance| / (sigma0 2 sigma0 L / E)
  double front_error = 0.0;                          // |front - exact| at 0.5 L/c, in dx
  bool blew_up = false;
  double blow_up_time = 0.0;
  // histories (every few steps)
  std::vector<double> t, v_loaded, v_loaded_exact, s_fixed, s_fixed_exact, energy_error, e1_t;
};

BarResult run_bar(const BarRun& r, const std::string& case_file, const std::vector<double>& snapshots) {
  const double dx = kL / r.n;
  std::vector<std::string> set = {
      fmt::format("geometry.spacing={}", dx),
      fmt::format("time.cfl={}", r.cfl),
      fmt::format("time.end={}", r.end),
      fmt::format("boundary.1.stress.xx={}", r.sign * kSigma0),
      "output.times=[]",
  };
  const double rise = r.smooth ? kTransit / 4.0 : 0.0;
  if (r.smooth) {
    set.emplace_back("functions.load.type=\"smoothstep\"");
    set.emplace_back(fmt::format("functions.load.duration={}", rise));
  }
  if (r.collocated) set.emplace_back("solver.scheme=\"collocated\"");
  const CaseDocument doc = load_case_document(case_file, set);
  CaseSetup<1> setup = read_case<1>(doc);
  Simulation<1> solver(setup);
  const analytic::ElasticBar exact{kL, kC, kRho, r.sign * kSigma0, rise};
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  std::size_t loaded = 0, fixed = 0;
  for (std::size_t i = 0; i < nn; ++i) {
    if (nodes.position[i][0] > nodes.position[loaded][0]) loaded = i;
    if (nodes.position[i][0] < nodes.position[fixed][0]) fixed = i;
  }
  const double scale = std::abs(kSigma0) * 2.0 * std::abs(kSigma0) * kL / kE;

  BarResult out;
  auto e1_now = [&](double t) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < nn; ++i) {
      const double ref = exact.stress(nodes.position[i][0], t);
      num += std::abs(solver.node_stress()(i, StressComponent::xx) - ref);
      den += std::abs(ref);
    }
    return den > 0.0 ? num / den : num;
  };
  const long steps = static_cast<long>(std::llround(r.end / solver.dt()));
  const long record_every = std::max(1L, steps / 800);
  const long zigzag_every = std::max(1L, static_cast<long>(std::llround(0.25 * kTransit / solver.dt())));
  std::size_t next_snap = 0;
  for (long n = 0; n <= steps; ++n) {
    if (n > 0) {
      try {
        solver.step();
      } catch (const SolverError&) {
        out.blew_up = true;
        out.blow_up_time = solver.time() / kTransit;
        break;
      }
    }
    const double t = solver.time();
    for (std::size_t i = 0; i < nn; ++i) {
      out.max_abs_stress =
          std::max(out.max_abs_stress, std::abs(solver.node_stress()(i, StressComponent::xx)) / kSigma0);
    }
    if (!std::isfinite(out.max_abs_stress) || out.max_abs_stress > 1e6) {
      out.blew_up = true;
      out.blow_up_time = t / kTransit;
      break;
    }
    if (n % record_every == 0 || n == steps) {
      const EnergyBalance e = solver.energy();
      const double err = std::abs(e.imbalance()) / scale;
      out.max_energy_error = std::max(out.max_energy_error, err);
      out.t.push_back(t / kTransit);
      out.v_loaded.push_back(solver.node_velocity()(loaded, 0));
      out.v_loaded_exact.push_back(exact.velocity(kL, t));
      out.s_fixed.push_back(solver.node_stress()(fixed, StressComponent::xx));
      out.s_fixed_exact.push_back(exact.stress(0.0, t));
      out.energy_error.push_back(e.imbalance() / scale);
      out.e1_t.push_back(e1_now(t));
    }
    if (n % zigzag_every == 0 && n > 0) {
      // High-frequency content: RMS of the nodal second difference away from the fronts.
      double sum = 0.0;
      int count = 0;
      for (std::size_t i = 1; i + 1 < nn; ++i) {
        if (exact.distance_to_front(nodes.position[i][0], t) <= 3.0 * dx) continue;
        const double s = solver.node_stress()(i, StressComponent::xx);
        const double zz = s - 0.5 * (solver.node_stress()(i - 1, StressComponent::xx) +
                                     solver.node_stress()(i + 1, StressComponent::xx));
        sum += zz * zz;
        ++count;
      }
      if (count > 0) {
        const double zig = std::sqrt(sum / count) / kSigma0;
        out.max_zigzag = std::max(out.max_zigzag, zig);
        if (t <= 5.0 * kTransit) out.zigzag_early = std::max(out.zigzag_early, zig);
        if (t >= r.end - 5.0 * kTransit) out.zigzag_late = std::max(out.zigzag_late, zig);
      }
    }
    while (next_snap < snapshots.size() && t >= snapshots[next_snap] * kTransit - 1e-9) {
      out.snapshot_times.push_back(t / kTransit);
      out.snapshot_e1.push_back(e1_now(t));
      std::vector<double> xs, ss, es;
      for (std::size_t i = 0; i < nn; ++i) {
        xs.push_back(nodes.position[i][0]);
        ss.push_back(solver.node_stress()(i, StressComponent::xx));
        es.push_back(exact.stress(nodes.position[i][0], t));
      }
      if (std::abs(snapshots[next_snap] - 0.5) < 1e-9 && !r.smooth) {
        // Front: where sigma first crosses half the jump, scanning from the fixed end.
        double front = kL;
        for (std::size_t i = 0; i + 1 < nn; ++i) {
          const double a = ss[i] / (r.sign * kSigma0), b = ss[i + 1] / (r.sign * kSigma0);
          if (a < 0.5 && b >= 0.5) {
            front = xs[i] + (0.5 - a) / (b - a) * (xs[i + 1] - xs[i]);
            break;
          }
        }
        out.front_error = std::abs(front - (kL - kC * t)) / dx;
      }
      out.x.push_back(std::move(xs));
      out.sigma.push_back(std::move(ss));
      out.exact.push_back(std::move(es));
      ++next_snap;
    }
  }
  return out;
}

void write_profiles(const std::string& file, const BarResult& r) {
  std::ofstream f(file);
  f << "snapshot_LC,x,sigma,sigma_exact\n";
  for (std::size_t s = 0; s < r.x.size(); ++s) {
    for (std::size_t i = 0; i < r.x[s].size(); ++i) {
      f << fmt::format("{:.6g},{:.8g},{:.10g},{:.10g}\n", r.snapshot_times[s], r.x[s][i], r.sigma[s][i], r.exact[s][i]);
    }
  }
}

void write_history(const std::string& file, const BarResult& r) {
  std::ofstream f(file);
  f << "t_LC,v_loaded,v_loaded_exact,sigma_fixed,sigma_fixed_exact,energy_error,e1\n";
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    f << fmt::format("{:.8g},{:.10g},{:.10g},{:.10g},{:.10g},{:.6g},{:.6g}\n", r.t[k], r.v_loaded[k],
                     r.v_loaded_exact[k], r.s_fixed[k], r.s_fixed_exact[k], r.energy_error[k], r.e1_t[k]);
  }
}

}  // namespace

CaseReport validate_case01(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "01";
  rep.title = "1D elastic bar: test of stability (V1)";
  rep.reference = "exact image-series solution (docs/cases.md Case 1), revised acceptance";
  const std::string case_file = (fs::path(opt.cases_dir) / "01_elastic_bar_1d.toml").string();
  const double c_max = 1.2;  // largest Courant number claimed in 1D (method-notes §0.3 item 4)

  // ---- accuracy on the smooth load, three resolutions
  const std::vector<int> ns = {100, 200, 400};
  const std::vector<double> tol = {0.08, 0.03, 0.01};
  std::vector<double> e1;
  for (std::size_t k = 0; k < ns.size(); ++k) {
    BarRun r{ns[k], 0.5, 1.0, true, false, 3.5 * kTransit};
    const BarResult res = run_bar(r, case_file, {0.5, 1.5, 3.5});
    e1.push_back(res.snapshot_e1.back());
    write_profiles(fmt::format("{}/smooth_N{}.csv", dir, ns[k]), res);
    rep.metrics.push_back(
        metric(fmt::format("smooth load: e1(sigma) at 3.5 L/c, N = {}", ns[k]), e1.back(), "<=", tol[k], ""));
  }
  rep.metrics.push_back(metric("smooth load: observed order, N = 200 -> 400", std::log2(e1[1] / e1[2]), ">=", 1.7, ""));
  rep.metrics.push_back(metric("smooth load: observed order, N = 100 -> 200", std::log2(e1[0] / e1[1]), "", 0.0, ""));

  // ---- stability on the step load: tension and compression, N = 100 and 400, C = 0.5 and C_max
  const std::vector<double> snaps = {0.5, 1.5, 3.5, 19.5};
  double worst_growth = 0;
  double worst_stress = 0, worst_zigzag = 0, worst_energy = 0, worst_front = 0, mirror = 0;
  bool decreasing = true, blew = false;
  for (double cfl : {0.5, c_max}) {
    std::vector<BarResult> tension;
    for (int n : {100, 400}) {
      for (double sign : {1.0, -1.0}) {
        BarRun r{n, cfl, sign, false, false, 20.0 * kTransit};
        BarResult res = run_bar(r, case_file, snaps);
        blew = blew || res.blew_up;
        worst_stress = std::max(worst_stress, res.max_abs_stress);
        worst_zigzag = std::max(worst_zigzag, res.max_zigzag);
        worst_growth = std::max(worst_growth, res.zigzag_late / std::max(res.zigzag_early, 1e-300));
        rep.notes.push_back(
            fmt::format("step load {}, N = {}, C = {}: zig-zag RMS max {:.4f} (first 5 L/c {:.4f}, "
                        "last 5 L/c {:.4f}), max |sigma|/sigma0 {:.3f}, energy error {:.4f}",
                        sign > 0 ? "tension" : "compression", n, cfl, res.max_zigzag, res.zigzag_early, res.zigzag_late,
                        res.max_abs_stress, res.max_energy_error));
        worst_energy = std::max(worst_energy, res.max_energy_error);
        worst_front = std::max(worst_front, res.front_error);
        if (sign > 0) {
          write_history(fmt::format("{}/step_tension_N{}_C{}.csv", dir, n, cfl), res);
          write_profiles(fmt::format("{}/step_tension_profiles_N{}_C{}.csv", dir, n, cfl), res);
          tension.push_back(std::move(res));
        } else {
          // Fixed particles: the problem is linear, compression must mirror tension.
          const BarResult& t = tension.back();
          for (std::size_t s = 0; s < std::min(t.sigma.size(), res.sigma.size()); ++s) {
            for (std::size_t i = 0; i < t.sigma[s].size(); ++i) {
              mirror = std::max(mirror, std::abs(t.sigma[s][i] + res.sigma[s][i]) / kSigma0);
            }
          }
        }
      }
    }
    for (std::size_t s = 0; s < snaps.size(); ++s) {
      if (s < tension[0].snapshot_e1.size() && s < tension[1].snapshot_e1.size() &&
          !(tension[1].snapshot_e1[s] < tension[0].snapshot_e1[s])) {
        decreasing = false;
      }
      rep.notes.push_back(fmt::format("step load, C = {}: e1 at {} L/c is {:.4f} (N = 100) and {:.4f} (N = 400)", cfl,
                                      snaps[s], tension[0].snapshot_e1[s], tension[1].snapshot_e1[s]));
    }
  }
  rep.metrics.push_back(metric("step load: blow-up in any of the 8 runs (1 = yes)", blew ? 1.0 : 0.0, "<=", 0.0, ""));
  rep.metrics.push_back(metric("step load: max |sigma| / |sigma0| over 20 L/c", worst_stress, "<=", 2.6, ""));
  {
    Metric zig = metric("step load: max nodal zig-zag RMS / |sigma0| (3 dx from fronts)", worst_zigzag, "<=", 0.01, "");
    if (!zig.pass() && worst_growth < 1.0) {
      // Measured: the peak comes from the dispersive ringing behind the step front during the
      // first transits at N = 100 (about 1.02 %), and decays afterwards (no growth); N = 400
      // stays near 0.2 %. Not met as written, reported as such.
      zig.known_deviation = fmt::format(
          "peak during the first 5 L/c at N = 100 from the dispersive ringing of the step, "
          "decaying afterwards (late/early ratio {:.2f}); N = 400 meets it",
          worst_growth);
    }
    rep.metrics.push_back(zig);
  }
  rep.metrics.push_back(
      metric("step load: zig-zag growth, max over runs of (last 5 L/c) / (first 5 L/c)", worst_growth, "", 0.0, ""));
  rep.metrics.push_back(
      metric("step load: max energy-balance error / (sigma0 2 sigma0 L/E)", worst_energy, "<=", 0.02, ""));
  rep.metrics.push_back(metric("step load: front position error at 0.5 L/c", worst_front, "<=", 3.0, "dx"));
  rep.metrics.push_back(
      metric("step load: e1 decreases with N at every snapshot (1 = yes)", decreasing ? 1.0 : 0.0, ">=", 1.0, ""));
  rep.metrics.push_back(metric("tension/compression mirror: max |s_t + s_c| / sigma0", mirror, "<=", 1e-9, ""));

  // ---- single-set (collocated) comparison, reported only (method-notes §0.3 item 6)
  {
    BarRun smooth{100, 0.5, 1.0, true, true, 3.5 * kTransit};
    const BarResult s = run_bar(smooth, case_file, {3.5});
    BarRun step{100, 0.5, 1.0, false, true, 20.0 * kTransit};
    const BarResult st = run_bar(step, case_file, snaps);
    write_history(fmt::format("{}/collocated_step_tension_N100_C0.5.csv", dir), st);
    rep.metrics.push_back(metric("single set (collocated), smooth load: e1 at 3.5 L/c, N = 100",
                                 s.snapshot_e1.empty() ? NAN : s.snapshot_e1.back(), "", 0, ""));
    rep.metrics.push_back(
        metric("single set (collocated), step load: max |sigma|/|sigma0| over 20 L/c", st.max_abs_stress, "", 0, ""));
    rep.metrics.push_back(
        metric("single set (collocated), step load: max energy error", st.max_energy_error, "", 0, ""));
    rep.notes.push_back(
        st.blew_up ? fmt::format("the single-set run blew up at {:.2f} L/c", st.blow_up_time)
                   : "the single-set run stayed bounded over 20 L/c (fixed particles: the problem is linear, so "
                     "this compares time integration and boundary closure, not the tensile instability; "
                     "see method-notes §0.3 item 6)");
  }
  std::string note;
  if (opt.plots && run_plot_script("plot_case01.py", dir, note)) {
    rep.plots = {"case01/profiles_smooth.png", "case01/histories_step.png", "case01/energy_error.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
