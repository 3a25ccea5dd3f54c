// Thesis case 13: consolidation of a saturated soil column (docs/cases.md Case 13, V3 solver),
// against Terzaghi's series with Biot's c_v, convolved exactly with the case file's 0.5 s load
// history (a smoothstep: see docs/cases.md Case 13).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "validation/analytic_saturated.hpp"
#include "validation/saturated_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kH = 10.0, kQ = 5.0e3, kEnd = 40.0;
const std::vector<double> kTv = {0.05, 0.10, 0.20, 0.50, 1.00};

analytic::SaturatedColumn column13() {
  analytic::SaturatedColumn c;
  c.height = kH;
  c.constrained = 3.0e7 * 0.8 / (1.2 * 0.6);
  c.storage = 1.0e8 / 0.3;
  c.permeability = 1.0e-3 / (1000.0 * 9.81);
  c.density = 1700.0;
  return c;
}

// The reference for the case file's loading: the load function of the loaded top, a "ramp" or
// a "smoothstep" (anything else cannot be compared with the closed form).
analytic::Terzaghi reference13(const CaseSetup<1>& setup, const std::string& case_file) {
  for (const auto& b : setup.boundaries) {
    if (b.stress.empty()) continue;
    if (b.function < 0) return analytic::Terzaghi{column13(), kQ, 0.0};
    const TimeFunction& f = setup.functions[static_cast<std::size_t>(b.function)];
    if (f.start != 0.0 || f.value != 1.0 ||
        (f.kind != TimeFunction::Kind::ramp && f.kind != TimeFunction::Kind::smoothstep)) {
      throw SolverError(case_file + ": case 13's load must rise by a \"ramp\" or \"smoothstep\" from t = 0 to 1");
    }
    return analytic::Terzaghi{column13(), kQ, f.duration, f.kind};
  }
  throw SolverError(case_file + ": case 13 has no loaded face");
}

struct ColumnRun {
  double dx = 0.0;
  std::vector<double> depth;                        // z = H - x of each node, sorted by depth
  std::vector<std::vector<double>> iso;             // p_w/p0 at each tabulated time (per node)
  std::vector<double> iso_time;                     // actual solver time of each isochrone
  std::vector<double> t, u_h, s_h, p25, p50, p100;  // histories
  double einf[5] = {}, e2_num = 0.0, e2_den = 0.0;
  double e2_late_num = 0.0, e2_late_den = 0.0;  // isochrones T_v >= 0.2 only
  double u_err = 0.0, s_err = 0.0, checker = 0.0;
  double s_final = 0.0;
  long iterations_max = 0;
  double iterations_mean = 0.0, residual = 0.0, pressure_share = 0.0, seconds = 0.0;
};

ColumnRun run_column(const std::string& case_file, double dx) {
  const std::vector<std::string> set = {fmt::format("geometry.spacing={}", dx), fmt::format("time.end={}", kEnd),
                                        "output.times=[]"};
  const CaseDocument doc = load_case_document(case_file, set);
  CaseSetup<1> setup = read_case<1>(doc);
  Simulation<1> solver(setup);
  const analytic::SaturatedColumn col = column13();
  const analytic::Terzaghi ref = reference13(setup, case_file);
  const double p0 = kQ * col.skempton();
  const double sinf = ref.final_settlement();
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  std::vector<std::size_t> order(nn);
  for (std::size_t i = 0; i < nn; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return nodes.position[a][0] > nodes.position[b][0]; });
  ColumnRun out;
  out.dx = dx;
  for (std::size_t i : order) out.depth.push_back(kH - nodes.position[i][0]);
  const std::size_t top = order.front();
  auto pw = [&](std::size_t k) { return solver.node_pore_pressure()[order[k]]; };
  auto nearest = [&](double z) {
    std::size_t best = 0;
    for (std::size_t k = 0; k < nn; ++k) {
      if (std::abs(out.depth[k] - z) < std::abs(out.depth[best] - z)) best = k;
    }
    return best;
  };
  const std::size_t k25 = nearest(0.25 * kH), k50 = nearest(0.5 * kH), k100 = nearest(kH);

  std::vector<double> times;
  for (double tv : kTv) times.push_back(tv * kH * kH / col.cv());
  std::size_t next = 0;
  const long steps = static_cast<long>(std::ceil(kEnd / solver.dt() - 1e-9));
  const long record_every = std::max(1L, steps / 800);
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n <= steps; ++n) {
    if (n > 0) solver.step();
    const double t = solver.time();
    double mean_p = 0.0;
    for (std::size_t i = 0; i < nn; ++i) mean_p += nodes.volume[i] * solver.node_pore_pressure()[i];
    mean_p /= kH;
    const double fraction = ref.fraction(t);
    const double u_h = fraction > 0.0 ? 1.0 - mean_p / (p0 * fraction) : 0.0;
    const double s_h = -solver.node_displacement()(top, 0);
    if (t >= 1.0) {  // the degree of consolidation is compared once the load is on
      out.u_err = std::max(out.u_err, std::abs(u_h - ref.degree(t)));
    }
    out.s_err = std::max(out.s_err, std::abs(s_h - ref.settlement(t)) / sinf);
    if (n % record_every == 0 || n == steps) {
      out.t.push_back(t);
      out.u_h.push_back(u_h);
      out.s_h.push_back(s_h);
      out.p25.push_back(pw(k25) / p0);
      out.p50.push_back(pw(k50) / p0);
      out.p100.push_back(pw(k100) / p0);
    }
    if (next < times.size() && t >= times[next] - 1e-12) {
      std::vector<double> prof(nn);
      double einf = 0.0;
      for (std::size_t k = 0; k < nn; ++k) {
        prof[k] = pw(k) / p0;
        const double r = ref.pressure(out.depth[k], t) / p0;
        // docs/cases.md: at T_v = 0.05 the two particle rows next to the drained top are excluded.
        if (!(next == 0 && out.depth[k] < 2.5 * dx)) einf = std::max(einf, std::abs(prof[k] - r));
        out.e2_num += (prof[k] - r) * (prof[k] - r);
        out.e2_den += r * r;
        if (next >= 2) {
          out.e2_late_num += (prof[k] - r) * (prof[k] - r);
          out.e2_late_den += r * r;
        }
      }
      // Checkerboard: distance from the mean of the lattice neighbours, away from the top.
      for (std::size_t k = 1; k + 1 < nn; ++k) {
        if (out.depth[k] > 3.0 * dx) {
          out.checker = std::max(out.checker, std::abs(prof[k] - 0.5 * (prof[k - 1] + prof[k + 1])));
        }
      }
      out.einf[next] = einf;
      out.iso.push_back(prof);
      out.iso_time.push_back(t);
      ++next;
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.s_final = -solver.node_displacement()(top, 0);
  const PressureSolveStats* ps = &pressure_stage(solver, "case 13").stats();
  if (ps == nullptr) throw SolverError("the case file is not a V3 (saturated) case");
  out.iterations_max = ps->max_iterations;
  out.iterations_mean = ps->mean_iterations();
  out.residual = ps->max_error;
  out.pressure_share = pressure_stage(solver, "case 13").seconds() / out.seconds;
  return out;
}

void write_run(const std::string& dir, const ColumnRun& r, const analytic::Terzaghi& ref) {
  const double p0 = kQ * ref.col.skempton();
  {
    std::ofstream f(fmt::format("{}/isochrones_dx{}.csv", dir, r.dx));
    f << "z_over_H";
    for (std::size_t j = 0; j < r.iso.size(); ++j) f << fmt::format(",num_Tv{},ref_Tv{}", kTv[j], kTv[j]);
    f << "\n";
    for (std::size_t k = 0; k < r.depth.size(); ++k) {
      f << fmt::format("{:.6g}", r.depth[k] / kH);
      for (std::size_t j = 0; j < r.iso.size(); ++j) {
        f << fmt::format(",{:.8g},{:.8g}", r.iso[j][k], ref.pressure(r.depth[k], r.iso_time[j]) / p0);
      }
      f << "\n";
    }
  }
  std::ofstream f(fmt::format("{}/history_dx{}.csv", dir, r.dx));
  f << "t,U_num,U_ref,S_num,S_ref,p25_num,p25_ref,p50_num,p50_ref,p100_num,p100_ref\n";
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const double t = r.t[k];
    f << fmt::format("{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", t, r.u_h[k],
                     ref.degree(t), r.s_h[k], ref.settlement(t), r.p25[k], ref.pressure(0.25 * kH, t) / p0, r.p50[k],
                     ref.pressure(0.5 * kH, t) / p0, r.p100[k], ref.pressure(kH, t) / p0);
  }
}

}  // namespace

CaseReport validate_case13(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "13";
  rep.title = "Consolidation of a saturated soil column (V3)";
  rep.reference =
      "Terzaghi series with Biot's c_v = 3.089 m^2/s and p0 = q Q/(M+Q) = 4.545 kPa "
      "(docs/cases.md Case 13), convolved exactly with the case file's 0.5 s load history "
      "(src/validation/analytic_saturated.hpp)";
  const std::string case_file = (fs::path(opt.cases_dir) / "13_consolidation_column.toml").string();
  const analytic::Terzaghi ref = reference13(read_case<1>(load_case_document(case_file, {})), case_file);
  std::vector<double> spacings = {0.2, 0.1};
  if (opt.full) spacings.push_back(0.05);
  std::vector<ColumnRun> runs;
  for (double dx : spacings) {
    runs.push_back(run_column(case_file, dx));
    write_run(dir, runs.back(), ref);
  }
  const ColumnRun& b = runs[1];  // baseline dx = 0.1 m
  for (std::size_t j = 0; j < kTv.size(); ++j) {
    rep.metrics.push_back(metric(fmt::format("dx = 0.1: isochrone T_v = {}: e_inf / p0{}", kTv[j],
                                             j == 0 ? " (two rows below the drained top excluded)" : ""),
                                 b.einf[j], "<=", 0.03, ""));
  }
  rep.metrics.push_back(metric("dx = 0.1: max |U_h - U| over t in [1, 40] s", b.u_err, "<=", 0.02, ""));
  rep.metrics.push_back(metric("dx = 0.1: max |S_h - S| / S_inf over the run", b.s_err, "<=", 0.03, ""));
  rep.metrics.push_back(
      metric("dx = 0.1: checkerboard, max |p_I - mean of neighbours| / p0 (below 3 dx)", b.checker, "<=", 0.01, ""));
  std::string conv;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const double e2 = std::sqrt(runs[k].e2_num / runs[k].e2_den);
    conv += fmt::format("{}dx = {}: e2 = {:.3e}", k ? ", " : "", runs[k].dx, e2);
    rep.metrics.push_back(metric(fmt::format("dx = {}: e2 over the five isochrones", runs[k].dx), e2, "", 0, ""));
  }
  for (std::size_t k = 0; k + 1 < runs.size(); ++k) {
    const double ec = std::sqrt(runs[k].e2_num / runs[k].e2_den),
                 ef = std::sqrt(runs[k + 1].e2_num / runs[k + 1].e2_den);
    const double order = std::log(ec / ef) / std::log(runs[k].dx / runs[k + 1].dx);
    Metric m =
        metric(fmt::format("observed order of e2 (all five isochrones), dx {} -> {}", runs[k].dx, runs[k + 1].dx),
               order, ">=", 1.0, "");
    m.known_deviation =
        "the T_v = 0.05 and 0.1 isochrones (t = 1.6 and 3.2 s) carry the undrained free vibration that the 0.5 s "
        "load rise leaves (first-mode shape, period about 4H/V_c = 0.086 s, largest at the base: -1.3e-4 p0 at "
        "t = 1.6 s for dx = 0.05 under the case's smoothstep, 5.4e-3 p0 under a linear ramp). It is mixture "
        "inertia - part of the u-p_w dynamics, not of the quasi-static Terzaghi reference - and the time "
        "integration damps it less as dx and dt shrink, so at dx = 0.05 it is as large as the discretisation "
        "error (e2 8.4e-5, 3.1e-3 under the linear ramp). The order over T_v >= 0.2, where it has decayed, is the "
        "next metric";
    if (!m.pass())
      rep.metrics.push_back(m);
    else
      rep.metrics.push_back(metric(m.name, order, ">=", 1.0, ""));
    const double lc = std::sqrt(runs[k].e2_late_num / runs[k].e2_late_den);
    const double lf = std::sqrt(runs[k + 1].e2_late_num / runs[k + 1].e2_late_den);
    rep.metrics.push_back(metric(
        fmt::format("observed order of e2 over the isochrones T_v >= 0.2, dx {} -> {}", runs[k].dx, runs[k + 1].dx),
        std::log(lc / lf) / std::log(runs[k].dx / runs[k + 1].dx), ">=", 1.0, ""));
    conv += fmt::format("; T_v >= 0.2: e2 {:.3e} -> {:.3e}", lc, lf);
  }
  rep.notes.push_back("convergence: " + conv);
  for (const auto& r : runs) {
    rep.notes.push_back(fmt::format(
        "dx = {}: e_inf/p0 at T_v = 0.05/0.1/0.2/0.5/1 = {:.2e} / {:.2e} / {:.2e} / {:.2e} / {:.2e}; max|U_h - U| = "
        "{:.2e}; "
        "S(40 s) = {:.4e} m (exact {:.4e}); PCG (Jacobi) iterations mean {:.1f}, max {}, max relative residual "
        "{:.2e}; pressure step {:.0f} % of the loop time ({:.1f} s)",
        r.dx, r.einf[0], r.einf[1], r.einf[2], r.einf[3], r.einf[4], r.u_err, r.s_final, ref.settlement(kEnd),
        r.iterations_mean, r.iterations_max, r.residual, 100.0 * r.pressure_share, r.seconds));
  }
  rep.metrics.push_back(metric("dx = 0.1: PCG iterations per step, mean", b.iterations_mean, "", 0, ""));
  rep.metrics.push_back(metric("dx = 0.1: pressure step share of the loop time", b.pressure_share, "", 0, ""));
  if (!opt.full) rep.notes.push_back("quick mode: dx = 0.2 and 0.1 m; --full adds dx = 0.05 m");
  std::string note;
  if (opt.plots && run_plot_script("plot_case13.py", dir, note)) {
    rep.plots = {"case13/isochrones.png", "case13/histories.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
