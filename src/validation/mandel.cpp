// Mandel's problem with a force-driven rigid plate in small deformation (V3;
// cases/examples/mandel_2d.toml, method-notes §4.6): the Mandel-Cryer rise of the centre pore
// pressure, its peak and its time, and the plate's settlement, against the exact series
// (src/validation/analytic_saturated.hpp) convolved with the case's load ramp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/plate_stages.hpp"
#include "schemes/simulation.hpp"
#include "validation/analytic_saturated.hpp"
#include "validation/saturated_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

struct MandelRun {
  double dx = 0.0;
  std::vector<double> t, p, u;  // centre p_w (Pa), plate settlement (m, positive down)
  double peak = 0.0, peak_time = 0.0;
  double p_err = 0.0;  // max |p - p_exact| / p0 after the vibration has gone (t >= 0.3 s)
  double u_err = 0.0;  // max |u - u_exact| / u_drained over the same window
  double reaction = 0.0;
  long iterations_max = 0;
  double iterations_mean = 0.0, seconds = 0.0;
};

// The peak of a sampled history: a parabola fitted by least squares to the samples within 1 %
// of p0 of the largest one (the maximum is flat; its sample alone fixes the time to a sample).
void fit_peak(const std::vector<double>& t, const std::vector<double>& p, double p0, double t_from, double& peak,
              double& time) {
  std::size_t k = 0;
  bool any = false;
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (t[j] < t_from) continue;
    if (!any || p[j] > p[k]) k = j;
    any = true;
  }
  if (!any) throw SolverError("Mandel: no samples after the vibration");
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  const double tk = t[k];
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (t[j] < t_from || p[j] < p[k] - 0.01 * p0) continue;
    const double s = t[j] - tk;
    const Eigen::Vector3d row(1.0, s, s * s);
    a += row * row.transpose();
    b += row * p[j];
  }
  const Eigen::Vector3d c = a.ldlt().solve(b);
  if (!(c[2] < 0.0)) {
    peak = p[k];
    time = tk;
    return;
  }
  const double s = -c[1] / (2.0 * c[2]);
  peak = c[0] + c[1] * s + c[2] * s * s;
  time = tk + s;
}

MandelRun run_mandel(const std::string& case_file, double dx, double end, const analytic::Mandel& ref) {
  const std::vector<std::string> set = {fmt::format("geometry.spacing={}", dx), fmt::format("time.end={}", end),
                                        "output.times=[]"};
  const CaseDocument doc = load_case_document(case_file, set);
  CaseSetup<2> setup = read_case<2>(doc);
  Simulation<2> solver(setup);
  const auto* plates = solver.scheme().find<FinishRigidPlates>();
  if (plates == nullptr) throw SolverError("Mandel: the case has no rigid body");
  const auto& nodes = solver.nodes();
  std::size_t centre = 0;
  for (std::size_t i = 0; i < nodes.position.size(); ++i) {
    if (nodes.position[i].norm() < nodes.position[centre].norm()) centre = i;
  }
  const double p0 = ref.initial_pressure();
  const double u_drained = ref.strain(1e30);
  MandelRun out;
  out.dx = dx;
  const long steps = static_cast<long>(std::ceil(end / solver.dt() - 1e-9));
  for (auto* history : {&out.t, &out.p, &out.u}) history->reserve(static_cast<std::size_t>(steps) + 1);
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n <= steps; ++n) {
    if (n > 0) solver.step();
    const double t = solver.time();
    const double p = solver.node_pore_pressure()[centre];
    const double u = -plates->plates().plates()[0].state.offset[1];
    out.t.push_back(t);
    out.p.push_back(p);
    out.u.push_back(u);
    if (t >= 0.3) {
      out.p_err = std::max(out.p_err, std::abs(p - ref.pressure(0.0, t)) / p0);
      out.u_err = std::max(out.u_err, std::abs(u - ref.strain(t)) / u_drained);
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.reaction = plates->plates().plates()[0].state.force[1] / ref.force;
  fit_peak(out.t, out.p, p0, 0.3, out.peak, out.peak_time);
  const PorePressureStage<2>& stage = pressure_stage(solver, "Mandel");
  out.iterations_max = stage.stats().max_iterations;
  out.iterations_mean = stage.stats().mean_iterations();
  return out;
}

void write_run(const std::string& dir, const MandelRun& r, const analytic::Mandel& ref) {
  std::ofstream f(fmt::format("{}/history_dx{}.csv", dir, r.dx));
  f << "t,tc_over_a2,p_over_p0,p_exact_over_p0,settlement,settlement_exact\n";
  const double p0 = ref.initial_pressure(), rate = ref.consolidation();
  const std::size_t every = std::max<std::size_t>(1, r.t.size() / 1500);
  for (std::size_t j = 0; j < r.t.size(); j += every) {
    f << fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", r.t[j], r.t[j] * rate, r.p[j] / p0,
                     ref.pressure(0.0, r.t[j]) / p0, r.u[j], ref.strain(r.t[j]));
  }
}

}  // namespace

CaseReport validate_mandel(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "mandel";
  rep.title = "Mandel's problem: rigid plate under a constant force on saturated soil (V3, beyond the thesis)";
  rep.reference =
      "Mandel's exact series (Abousleiman et al. 1996), c = 0.1 m^2/s, p0 = F B (1 + nu_u)/(3a) = 4.994 kPa, "
      "convolved with the 0.05 s load ramp (src/validation/analytic_saturated.hpp)";
  const std::string case_file = (fs::path(opt.cases_dir) / ".." / "examples" / "mandel_2d.toml").string();
  const analytic::Mandel ref = analytic::mandel_example();
  const double p0 = ref.initial_pressure();
  // The exact peak of the ramped load, by golden-section search on its unimodal bump.
  double lo = 0.2, hi = 2.0;
  for (int it = 0; it < 80; ++it) {
    const double m1 = hi - 0.618033988749895 * (hi - lo), m2 = lo + 0.618033988749895 * (hi - lo);
    if (ref.pressure(0.0, m1) < ref.pressure(0.0, m2)) {
      lo = m1;
    } else {
      hi = m2;
    }
  }
  const double exact_time = 0.5 * (lo + hi), exact_peak = ref.pressure(0.0, exact_time) / p0;
  // Quick: to 1.5 s (t c/a^2 = 0.15, past the peak); full: to a^2/c.
  const double end = opt.full ? 10.0 : 1.5;
  std::vector<MandelRun> runs;
  for (const double dx : {0.05, 0.025}) {
    runs.push_back(run_mandel(case_file, dx, end, ref));
    write_run(dir, runs.back(), ref);
  }
  rep.metrics.push_back(metric("exact peak of the centre p_w / p0 (ramped load)", exact_peak, "", 0, ""));
  rep.metrics.push_back(metric("exact time of the peak", exact_time, "", 0, "s"));
  for (const MandelRun& r : runs) {
    const bool graded = r.dx == 0.025;
    const std::string tag = fmt::format("dx = {} (a/{:.0f})", r.dx, 1.0 / r.dx);
    const double rise = std::abs(r.peak / p0 / exact_peak - 1.0), when = std::abs(r.peak_time / exact_time - 1.0);
    rep.metrics.push_back(metric(tag + ": |centre p_w peak / exact - 1|", rise, graded ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + ": |peak time / exact - 1|", when, graded ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + ": centre p_w peak / p0", r.peak / p0, "", 0, ""));
    rep.metrics.push_back(metric(tag + ": peak time", r.peak_time, "", 0, "s"));
    rep.metrics.push_back(metric(tag + fmt::format(": max |p_w - exact| / p0 at the centre, t in [0.3, {}] s", end),
                                 r.p_err, "", 0, ""));
    rep.metrics.push_back(metric(tag + fmt::format(": max |settlement - exact| / drained settlement, t in [0.3, {}] s", end),
                                 r.u_err, "", 0, ""));
    rep.metrics.push_back(metric(tag + ": plate reaction / applied force at the end", r.reaction, "", 0, ""));
    rep.metrics.push_back(metric(tag + ": PCG iterations per step, mean", r.iterations_mean, "", 0, ""));
    rep.metrics.push_back(metric(tag + ": run time", r.seconds, "", 0, "s"));
  }
  rep.notes.push_back(
      "the tolerances (3 %, issue 15) are graded at dx = a/40; dx = a/20 is reported for the convergence. "
      "The peak is a least-squares parabola through the samples within 1 % of p0 of the largest.");
  if (!opt.full) rep.notes.push_back("quick mode: to t = 1.5 s (t c/a^2 = 0.15); --full runs to a^2/c = 10 s");
  std::string note;
  if (opt.plots && run_plot_script("plot_mandel.py", dir, note)) {
    rep.plots = {"casemandel/mandel.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
