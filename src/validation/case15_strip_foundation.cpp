// Thesis case 15: strip foundation on saturated soil (docs/cases.md Case 15, V3 solver, 2D): the
// undrained response (k = 1e-5 m/s, time average over 0.5-1.5 s) against the plane-strain FE
// table of docs/cases.md, and the drained end state (k = 1e-3 m/s, t = 130 s) against the drained
// settlements.
//
//
// The footing's edge node takes half the pressure (tributary average, docs/case-format.md) and
// displacements follow the stress points' velocity (docs/method-notes.md, "Displacements"):
// the edge no longer runs away. The storage equation takes the default, consistent rate
// (method-notes eq. (2.4.20)): with the nodes' divergence alone, the O(dt) nodal velocity that the
// two-step scheme keeps at a load jump in a steady state fed a steady Darcy flow and p_w never
// drained; see docs/VALIDATION.md, Case 15.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "validation/saturated_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kSigma0 = 5.0e3, kSurface = 10.0;
struct Point {
  const char* name;
  double x, depth, ref, tol;
};
// docs/cases.md Case 15, undrained p_w / sigma0 and the tolerance of each point.
const std::vector<Point> kPoints = {{"(0, 1 m)", 0.0, 1.0, 0.748, 0.15},
                                    {"(0, 2 m)", 0.0, 2.0, 0.605, 0.10},
                                    {"(0, 5 m)", 0.0, 5.0, 0.388, 0.10},
                                    {"(2 m, 2 m)", 2.0, 2.0, 0.512, 0.10},
                                    {"(5 m, 2 m)", 5.0, 2.0, 0.186, 0.0}};
constexpr double kUndrainedSettlement = 4.56e-4, kCentreDrained = 1.091e-3, kEdgeDrained = 6.96e-4;

std::size_t nearest(const ParticleSet<2>& nodes, double x, double y) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    if ((nodes.position[i] - Vec<2>(x, y)).norm() < (nodes.position[best] - Vec<2>(x, y)).norm()) best = i;
  }
  return best;
}

// max |p_I - mean of the 4 lattice neighbours| / sigma0 over nodes more than 3 dx from every face.
double checkerboard(const Simulation<2>& s, double dx) {
  const auto& nodes = s.nodes();
  const auto& pw = s.node_pore_pressure();
  double worst = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    const Vec<2>& x = nodes.position[i];
    if (x[0] < 3 * dx || x[1] < 3 * dx || x[0] > 10.0 - 3 * dx || x[1] > kSurface - 3 * dx) continue;
    double mean = 0.0;
    for (const Vec<2>& d : {Vec<2>(dx, 0), Vec<2>(-dx, 0), Vec<2>(0, dx), Vec<2>(0, -dx)}) {
      mean += 0.25 * pw[nearest(nodes, x[0] + d[0], x[1] + d[1])];
    }
    worst = std::max(worst, std::abs(pw[i] - mean) / kSigma0);
  }
  return worst;
}

// The odd-even (checkerboard) amplitude of p_w / sigma0: the fourth difference along x and y
// (saturated_common.hpp, as for Cases 16 and 17), exactly the amplitude of a node-to-node
// alternation and zero for any cubic field, over the nodes whose five-point stencils lie in the
// body, the drained surface nodes (p_w = 0, the boundary layer's pinned end) left out. The mean
// of 4 neighbours above also reads the curvature of a smooth field (Delta x^2 lap p / 4), which
// beside the footing edge is steep at t = 1.5 s: it is reported, not the criterion.
double alternation(const Simulation<2>& s, double dx) {
  const auto& nodes = s.nodes();
  const auto& pw = s.node_pore_pressure();
  std::vector<double> x(static_cast<std::size_t>(nodes.size())), y(x.size()), f(x.size());
  std::vector<bool> drained(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = nodes.position[i][0];
    y[i] = nodes.position[i][1];
    f[i] = pw[i] / kSigma0;
    drained[i] = std::abs(y[i] - kSurface) < 1e-6 * dx && x[i] > 3.0 + 1e-6 * dx;
  }
  return checkerboard_amplitude(x, y, f, dx, nullptr, &drained);
}

}  // namespace

CaseReport validate_case15(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "15";
  rep.title = "Strip foundation on saturated soil (V3, 2D)";
  rep.reference =
      "docs/cases.md Case 15: plane-strain FE undrained table (time average 0.5-1.5 s of the k = 1e-5 m/s "
      "run) and drained end-state settlements";
  const std::string case_file = (fs::path(opt.cases_dir) / "15_strip_foundation_saturated.toml").string();
  // Quick: 0.25 m, a lattice with a node on the footing edge (x = 3 m), which then takes half
  // the pressure (docs/case-format.md). At 0.5 m the undrained p_w at (0, 1 m) and the centre
  // settlement are 15.6 % and 10.2 % off (tolerances 15 and 10 %): too coarse under a 6 m strip.
  const double dx = opt.full ? 0.2 : 0.25;

  // ---- undrained check
  {
    const CaseDocument doc = load_case_document(
        case_file,
        {fmt::format("geometry.spacing={}", dx), "fluid.conductivity=1e-5", "time.end=1.5", "output.times=[]"});
    CaseSetup<2> setup = read_case<2>(doc);
    Simulation<2> solver(setup);
    const auto& nodes = solver.nodes();
    std::vector<std::size_t> idx;
    for (const auto& p : kPoints) idx.push_back(nearest(nodes, p.x, kSurface - p.depth));
    const std::size_t centre = nearest(nodes, 0.0, kSurface);
    std::vector<double> sum(kPoints.size(), 0.0);
    double settle = 0.0;
    long count = 0;
    std::ofstream hist(fmt::format("{}/undrained_dx{}.csv", dir, dx));
    hist << "t,centre_settlement";
    for (std::size_t k = 0; k < kPoints.size(); ++k) hist << ",p" << k;
    hist << "\n";
    while (solver.time() < 1.5 - 1e-9) {
      solver.step();
      if (solver.step_count() % 10 == 0) {
        hist << fmt::format("{:.5g},{:.6e}", solver.time(), -solver.node_displacement()(centre, 1));
        for (std::size_t k = 0; k < kPoints.size(); ++k)
          hist << fmt::format(",{:.6g}", solver.node_pore_pressure()[idx[k]] / kSigma0);
        hist << "\n";
      }
      if (solver.time() >= 0.5) {
        for (std::size_t k = 0; k < kPoints.size(); ++k) sum[k] += solver.node_pore_pressure()[idx[k]];
        settle += -solver.node_displacement()(centre, 1);
        ++count;
      }
    }
    for (std::size_t k = 0; k < kPoints.size(); ++k) {
      const double v = sum[k] / static_cast<double>(count) / kSigma0;
      const auto& p = kPoints[k];
      if (p.tol > 0.0) {
        rep.metrics.push_back(
            metric(fmt::format("undrained, dx = {}: p_w/sigma0 at {} relative error (FE {})", dx, p.name, p.ref),
                   std::abs(v - p.ref) / p.ref, "<=", p.tol, ""));
      }
      rep.notes.push_back(fmt::format("undrained, dx = {}: mean p_w/sigma0 over 0.5-1.5 s at {} = {:.4f} (FE {})", dx,
                                      p.name, v, p.ref));
    }
    const double s = settle / static_cast<double>(count);
    rep.metrics.push_back(metric(fmt::format("undrained, dx = {}: centre settlement relative error (FE 4.56e-4 m)", dx),
                                 std::abs(s - kUndrainedSettlement) / kUndrainedSettlement, "<=", 0.10, ""));
    rep.metrics.push_back(
        metric(fmt::format("undrained, dx = {}: checkerboard (max alternating p_w component / sigma0) at 1.5 s", dx),
               alternation(solver, dx), "<=", 0.01, ""));
    rep.metrics.push_back(metric(
        fmt::format("undrained, dx = {}: max|p_I - mean of 4 neighbours| / sigma0 at 1.5 s, > 3 dx from the faces "
                    "(curvature included)",
                    dx),
        checkerboard(solver, dx), "", 0.0, ""));
  }

  // ---- drained end state (k = 1e-3 m/s, 130 s)
  {
    const CaseDocument doc = load_case_document(case_file, {fmt::format("geometry.spacing={}", dx), "output.times=[]"});
    CaseSetup<2> setup = read_case<2>(doc);
    Simulation<2> solver(setup);
    const auto& nodes = solver.nodes();
    const std::size_t centre = nearest(nodes, 0.0, kSurface), edge = nearest(nodes, 3.0, kSurface);
    std::ofstream hist(fmt::format("{}/consolidation_dx{}.csv", dir, dx));
    hist << "t,centre_settlement,edge_settlement,max_pw\n";
    double last = 0.0, drop = 0.0, checker = 0.0, checker_mean4 = 0.0;
    // 1 s window means of the centre settlement (the raw signal carries the column's undrained
    // vibration) and the vibration's amplitude in the window 2-3 s.
    std::vector<double> window_sum(131, 0.0), window_count(131, 0.0);
    double vib_lo = 1e30, vib_hi = -1e30;
    const auto t0 = std::chrono::steady_clock::now();
    const long every = std::max(1L, static_cast<long>(0.1 / solver.dt()));
    while (solver.time() < 130.0 - 1e-9) {
      solver.step();
      if (solver.step_count() % every != 0) continue;
      const double sc = -solver.node_displacement()(centre, 1);
      double pmax = 0.0;
      for (double p : solver.node_pore_pressure()) pmax = std::max(pmax, std::abs(p));
      hist << fmt::format("{:.5g},{:.6e},{:.6e},{:.6g}\n", solver.time(), sc, -solver.node_displacement()(edge, 1),
                          pmax / kSigma0);
      if (solver.time() > 2.0) drop = std::max(drop, last - sc);  // consolidation settlement must not decrease
      const auto w = static_cast<std::size_t>(std::min(130.0, std::floor(solver.time())));
      window_sum[w] += sc;
      window_count[w] += 1.0;
      if (solver.time() > 2.0 && solver.time() < 3.0) {
        vib_lo = std::min(vib_lo, sc);
        vib_hi = std::max(vib_hi, sc);
      }
      last = sc;
      if (std::abs(solver.time() - 15.0) < 0.5 * static_cast<double>(every) * solver.dt()) {
        checker = alternation(solver, dx);
        checker_mean4 = checkerboard(solver, dx);
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double pmax = 0.0;
    for (double p : solver.node_pore_pressure()) pmax = std::max(pmax, std::abs(p));
    const double sc = -solver.node_displacement()(centre, 1), se = -solver.node_displacement()(edge, 1);
    rep.metrics.push_back(
        metric(fmt::format("drained, dx = {}: final centre settlement relative error (1.091e-3 m)", dx),
               std::abs(sc - kCentreDrained) / kCentreDrained, "<=", 0.05, ""));
    rep.metrics.push_back(metric(fmt::format("drained, dx = {}: final edge settlement relative error (6.96e-4 m)", dx),
                                 std::abs(se - kEdgeDrained) / kEdgeDrained, "<=", 0.05, ""));
    rep.metrics.push_back(
        metric(fmt::format("drained, dx = {}: max |p_w| / sigma0 at 130 s", dx), pmax / kSigma0, "<=", 0.01, ""));
    double window_drop = 0.0, previous = -1.0;
    for (std::size_t w = 2; w < 130; ++w) {
      if (window_count[w] == 0.0) continue;
      const double mean = window_sum[w] / window_count[w];
      if (previous >= 0.0) window_drop = std::max(window_drop, previous - mean);
      previous = mean;
    }
    Metric monotonic =
        metric(fmt::format("drained, dx = {}: largest decrease of the centre settlement after 2 s / S_final", dx),
               drop / sc, "<=", 0.0, "");
    if (!monotonic.pass() && window_drop <= 0.02 * sc) {
      monotonic.known_deviation = fmt::format(
          "the raw settlement carries the column's undrained vibration that the 0.1 s load ramp excites (half "
          "amplitude {:.0f} % of S_final between 2 and 3 s): the quasi-static FE reference has none, and in the "
          "v-p_w model with k = 1e-3 m/s almost nothing damps it; 1 s window means fall by at most {:.2g} % of "
          "S_final",
          50.0 * (vib_hi - vib_lo) / sc, 100.0 * window_drop / sc);
    }
    rep.metrics.push_back(monotonic);
    rep.metrics.push_back(metric(fmt::format("drained, dx = {}: largest decrease of 1 s window means of the centre "
                                             "settlement after 2 s / S_final",
                                             dx),
                                 window_drop / sc, "", 0.0, ""));
    rep.metrics.push_back(
        metric(fmt::format("drained, dx = {}: checkerboard (max alternating p_w component / sigma0) at 15 s", dx),
               checker, "<=", 0.01, ""));
    rep.metrics.push_back(
        metric(fmt::format("drained, dx = {}: max|p_I - mean of 4 neighbours| / sigma0 at 15 s (curvature included)", dx),
               checker_mean4, "", 0.0, ""));
    const PressureSolveStats* ps = &pressure_stage(solver, "case 15").stats();
    if (ps == nullptr) throw SolverError("case 15 is not a V3 case");
    rep.notes.push_back(
        fmt::format("drained, dx = {}: centre {:.4e} m, edge {:.4e} m at 130 s; {} nodes, PCG (Jacobi) "
                    "iterations mean {:.1f}, max {}, pressure step {:.0f} % of {:.0f} s",
                    dx, sc, se, nodes.size(), ps->mean_iterations(), ps->max_iterations,
                    100.0 * pressure_stage(solver, "case 15").seconds() / seconds, seconds));
  }
  if (!opt.full) rep.notes.push_back("quick mode: dx = 0.25 m; --full runs dx = 0.2 m (docs/cases.md)");
  return rep;
}

}  // namespace rktsph::validation
