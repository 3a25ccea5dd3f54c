// Thesis case 4: elastic vertical cut (docs/cases.md Case 4). (a) the group's set-up, gravity ramp
// with damping, against the FE reference points, the exact section equilibrium and the
// traction-free faces; (b) the exactly solvable variant (nu = 0, smooth base, sudden gravity)
// against its closed form over two periods.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "validation/cut_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kRho = 2000.0, kG = 9.81, kE = 8.0e7, kH = 10.0, kW = 10.0;
constexpr double kGammaH = kRho * kG * kH;  // rho g H = 196.2 kPa

struct RefPoint {
  double x, y, sxx, syy, sxy;  // kPa
};
// docs/cases.md Case 4(a): 9-node FE reference (kPa).
constexpr RefPoint kRefPoints[] = {
    {0.0, 5.0, -19.3, -101.2, 0.0}, {5.0, 5.0, -11.8, -102.3, -1.6}, {9.9, 5.0, 0.0, -76.9, -0.6},
    {0.0, 1.0, -68.0, -175.0, 0.0}, {5.0, 1.0, -62.6, -175.3, 14.4},
};

struct CaseA {
  double stress_err = 0.0;         // max |sigma - ref| / (rho g H) over the points and components
  double disp_err = 0.0;           // max relative displacement error
  double crest_err_relaxed = 0.0;  // crest u_x error at t = 1.2 s (just relaxed)
  double crest_drift = 0.0;        // d u_c / dt over the last 0.5 s, m/s
  double section_err = 0.0;        // max relative section-resultant error
  double face_res = 0.0, top_res = 0.0, face_res_above = 0.0;  // / (rho g H)
  // Well-posed face measures under the toe singularity (scripts/williams_corner.py), / (rho g H):
  // RMS over the face, max over y >= 2 dx, and the toe row (the stress-point row y = dx/2).
  double face_rms = 0.0, face_res_2dx = 0.0, face_toe_row = 0.0;
  std::vector<CutRun::FaceRow> face_rows;
  double ke_end = 0.0, ke_peak = 0.0;
  double vmax_end = 0.0, vmax_x = 0.0, vmax_y = 0.0;
  double seconds = 0.0;
  long steps = 0;
};

CaseA run_a(const std::string& file, double dx, const std::string& dir, std::vector<std::string>& notes) {
  // docs/cases.md's dt = 1e-3 s is a Courant number of 0.46 at dx = 0.5 m; finer spacings keep it.
  std::vector<std::string> over = {fmt::format("geometry.spacing={}", dx), "output.interval=0"};
  if (dx < 0.25 - 1e-12) over.push_back(fmt::format("time.dt={}", 1e-3 * dx / 0.5));
  const CutRun r = run_cut(file, over, 0.01);
  CaseA a;
  a.seconds = r.seconds;
  a.steps = r.steps;
  if (!r.error.empty()) {
    notes.push_back(fmt::format("4(a) dx = {} m stopped: {}", dx, r.error));
    a.stress_err = a.disp_err = a.section_err = NAN;
    return a;
  }
  const CutSnapshot& s = r.final_state;
  std::ofstream pts(fs::path(dir) / fmt::format("a_points_dx{}.csv", dx));
  pts << "x,y,component,reference_kPa,computed_kPa\n";
  for (const auto& p : kRefPoints) {
    const double c[3] = {bilinear(s, s.sxx, dx, p.x, p.y) / 1e3, bilinear(s, s.syy, dx, p.x, p.y) / 1e3,
                         bilinear(s, s.sxy, dx, p.x, p.y) / 1e3};
    const double ref[3] = {p.sxx, p.syy, p.sxy};
    const char* names[3] = {"sxx", "syy", "sxy"};
    for (int k = 0; k < 3; ++k) {
      a.stress_err = std::max(a.stress_err, std::abs(c[k] - ref[k]) * 1e3 / kGammaH);
      pts << fmt::format("{},{},{},{},{:.4f}\n", p.x, p.y, names[k], ref[k], c[k]);
    }
  }
  // Displacements (docs/cases.md): settlements at the top, outward face displacement.
  struct Disp {
    const char* name;
    double x, y, ref;
    bool horizontal;
  };
  const Disp disps[] = {{"top settlement at x = 0", 0.0, kH, 1.019e-2, false},
                        {"top settlement at the crest", kW, kH, 0.998e-2, false},
                        {"face u_x at the crest", kW, kH, 1.76e-3, true},
                        {"face u_x at mid-height", kW, 0.5 * kH, 3.58e-3, true}};
  std::ofstream dsp(fs::path(dir) / fmt::format("a_displacements_dx{}.csv", dx));
  dsp << "point,reference_m,computed_m\n";
  for (const auto& d : disps) {
    const double v = d.horizontal ? at_node(s, s.ux, d.x, d.y) : -at_node(s, s.uy, d.x, d.y);
    a.disp_err = std::max(a.disp_err, std::abs(v - d.ref) / d.ref);
    dsp << fmt::format("{},{},{:.6g}\n", d.name, d.ref, v);
  }
  // Drift of the crest after the relaxation (method-notes §0.3 item 8: the steady flow at the toe).
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    if (r.t[k] >= 1.2 - 1e-9) {
      a.crest_err_relaxed = std::abs(r.uc[k] - 1.76e-3) / 1.76e-3;
      break;
    }
  }
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    if (r.t[k] >= r.t.back() - 0.5 - 1e-9) {
      a.crest_drift = (r.uc.back() - r.uc[k]) / (r.t.back() - r.t[k]);
      break;
    }
  }
  // Section resultants: trapezoidal sum of nodal sigma_yy along each node row.
  std::ofstream sec(fs::path(dir) / fmt::format("a_sections_dx{}.csv", dx));
  sec << "y,resultant_kN,exact_kN\n";
  for (double y = 0.0; y < kH - 0.5 * dx; y += dx) {
    std::vector<double> xs, fs_;
    row_profile(s, s.syy, y, dx, xs, fs_);
    double sum = 0.0;
    for (std::size_t k = 0; k + 1 < xs.size(); ++k) sum += 0.5 * (fs_[k] + fs_[k + 1]) * (xs[k + 1] - xs[k]);
    const double exact = -kRho * kG * kW * (kH - y);
    a.section_err = std::max(a.section_err, std::abs(sum - exact) / std::abs(exact));
    sec << fmt::format("{},{:.6g},{:.6g}\n", y, sum / 1e3, exact / 1e3);
  }
  a.face_res = r.face_residual / kGammaH;
  a.face_res_above = r.face_residual_above_toe / kGammaH;
  a.top_res = r.top_residual / kGammaH;
  a.face_rms = r.face_residual_rms / kGammaH;
  a.face_res_2dx = r.face_residual_beyond_2dx / kGammaH;
  a.face_rows = r.face_rows;
  if (!r.face_rows.empty()) {
    a.face_toe_row = std::max(std::abs(r.face_rows.front().sn), std::abs(r.face_rows.front().st)) / kGammaH;
  }
  {
    std::ofstream fr(fs::path(dir) / fmt::format("a_face_residual_dx{}.csv", dx));
    fr << "y,sn_over_rhogH,st_over_rhogH,max_over_rhogH\n";
    for (const auto& row : r.face_rows) {
      fr << fmt::format("{},{:.6g},{:.6g},{:.6g}\n", row.y, row.sn / kGammaH, row.st / kGammaH,
                        std::max(std::abs(row.sn), std::abs(row.st)) / kGammaH);
    }
  }
  a.ke_end = r.ke.back();
  a.ke_peak = r.peak_ke;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double v = std::hypot(s.vx[i], s.vy[i]);
    if (v > a.vmax_end) {
      a.vmax_end = v;
      a.vmax_x = s.x[i];
      a.vmax_y = s.y[i];
    }
  }
  write_snapshot_csv((fs::path(dir) / fmt::format("a_final_dx{}.csv", dx)).string(), s);
  write_history_csv((fs::path(dir) / fmt::format("a_history_dx{}.csv", dx)).string(), r);
  return a;
}

// Closed forms of docs/cases.md Case 4(b), u_y positive up (the top settles: negative).
double exact_base_stress(double t) {
  const double c = std::sqrt(kE / kRho), T = 4.0 * kH / c;
  const double tau = std::fmod(t, T);
  return tau <= 2.0 * kH / c ? -kRho * kG * c * tau : -kRho * kG * (4.0 * kH - c * tau);
}
double exact_top_uy(double t) {
  const double c = std::sqrt(kE / kRho), a = kH / c;
  const double tau = std::fmod(t, 4.0 * a);
  if (tau <= a) return -0.5 * kG * tau * tau;
  if (tau <= 3.0 * a) return -kRho * kG * kH * kH / kE + 0.5 * kG * (tau - 2.0 * a) * (tau - 2.0 * a);
  return -0.5 * kG * (4.0 * a - tau) * (4.0 * a - tau);
}

struct CaseB {
  double base_err = 0.0, top_err = 0.0, ux_ratio = 0.0, uniformity = 0.0;
  double seconds = 0.0;
  long steps = 0;
  std::vector<double> base_centre;  // the vertical stress at the base's centre node, every step (Pa)
};

// Case 4(b) in Dim = 2 or 3: the block [0, W]^(Dim-1) x [0, H], the last axis vertical, rollers
// under the base and on the faces x = 0 (and y = 0 in 3D), the other faces free. With nu = 0
// every vertical fibre is the same 1-D column, so the closed form holds in 3D unchanged.
// Measured at three base and top points: in 2D x = 1, 5, 9.75 m; in 3D along the diagonal,
// (1, 1), (5, 5), (9.75, 9.75) m, from the corner on rollers to the edge where two free faces meet.
template <int Dim>
CaseB run_b(const std::string& file, double dx, const std::string& dir) {
  constexpr int V = Dim - 1;  // the vertical axis
  constexpr StressComponent kVertical = Dim == 2 ? StressComponent::yy : StressComponent::zz;
  const double xs[3] = {1.0, 5.0, 9.75};
  std::vector<std::size_t> base(3), top(3), face;
  std::vector<int> face_axis;
  std::vector<std::vector<std::size_t>> rows(4);  // nodes of the planes at height 0, 2.5, 5, 7.5 m
  const double c = std::sqrt(kE / kRho);
  CaseB b;
  const auto t0 = std::chrono::steady_clock::now();
  const CaseDocument doc = load_case_document(file, {fmt::format("geometry.spacing={}", dx), "output.interval=0"});
  CaseSetup<Dim> setup = read_case<Dim>(doc);
  const double end_time = setup.end_time;
  Simulation<Dim> solver(std::move(setup));
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  // The point at horizontal coordinate a (every horizontal axis) and height z.
  auto distance = [&](std::size_t i, double a, double z) {
    Vec<Dim> q = Vec<Dim>::Constant(a);
    q[V] = z;
    return (nodes.position[i] - q).norm();
  };
  for (int k = 0; k < 3; ++k) {
    double d0 = 1e300, d1 = 1e300;
    for (std::size_t i = 0; i < nn; ++i) {
      const double db = distance(i, xs[k], 0.0), dt_ = distance(i, xs[k], kH);
      if (db < d0 - 1e-9) {
        d0 = db;
        base[static_cast<std::size_t>(k)] = i;
      }
      if (dt_ < d1 - 1e-9) {
        d1 = dt_;
        top[static_cast<std::size_t>(k)] = i;
      }
    }
  }
  for (std::size_t i = 0; i < nn; ++i) {
    const auto& p = nodes.position[i];
    for (int d = 0; d < V; ++d) {
      if (std::abs(p[d] - kW) < 1e-9) {  // a free lateral face: u normal to it is spurious
        face.push_back(i);
        face_axis.push_back(d);
      }
    }
    for (std::size_t k = 0; k < 4; ++k) {
      if (std::abs(p[V] - 2.5 * static_cast<double>(k)) < 1e-9) rows[k].push_back(i);
    }
  }
  std::ofstream f(fs::path(dir) / fmt::format("b{}_history_dx{}.csv", Dim == 2 ? "" : "3d", dx));
  f << fmt::format("t,{0}_exact,{0}_x1,{0}_x5,{0}_x9.75,{1}_exact,{1}_x1,{1}_x5,{1}_x9.75,ux_face_max\n",
                   Dim == 2 ? "syy" : "szz", Dim == 2 ? "uy" : "uz");
  double max_uv = 0.0, max_ux = 0.0;
  const long steps = static_cast<long>(std::ceil(end_time / solver.dt() - 1e-9));
  try {
    for (long n = 1; n <= steps; ++n) {
      solver.step();
      const double t = solver.time();
      const double se = exact_base_stress(t), ue = exact_top_uy(t);
      // Exclude +-2 steps around the slope reversals of the base stress, t = k 2H/c.
      const double rev = 2.0 * kH / c;
      const bool near_rev = std::abs(t - rev * std::round(t / rev)) <= 2.0 * solver.dt() + 1e-12;
      double sv[3], uv[3];
      for (std::size_t k = 0; k < 3; ++k) {
        sv[k] = solver.node_stress()(base[k], kVertical);
        uv[k] = solver.node_displacement()(top[k], V);
        if (!near_rev) b.base_err = std::max(b.base_err, std::abs(sv[k] - se) / (2.0 * kGammaH));
        b.top_err = std::max(b.top_err, std::abs(uv[k] - ue) / (kGammaH * kH / kE));
      }
      b.base_centre.push_back(sv[1]);
      double ux = 0.0;
      for (std::size_t k = 0; k < face.size(); ++k)
        ux = std::max(ux, std::abs(solver.node_displacement()(face[k], face_axis[k])));
      for (std::size_t i = 0; i < nn; ++i) max_uv = std::max(max_uv, std::abs(solver.node_displacement()(i, V)));
      max_ux = std::max(max_ux, ux);
      for (const auto& row : rows) {
        double lo = 1e300, hi = -1e300;
        for (std::size_t i : row) {
          lo = std::min(lo, solver.node_stress()(i, kVertical));
          hi = std::max(hi, solver.node_stress()(i, kVertical));
        }
        b.uniformity = std::max(b.uniformity, (hi - lo) / kGammaH);
      }
      f << fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", t, se, sv[0], sv[1],
                       sv[2], ue, uv[0], uv[1], uv[2], ux);
    }
  } catch (const SolverError&) {
    b.base_err = b.top_err = NAN;
  }
  b.ux_ratio = max_uv > 0.0 ? max_ux / max_uv : NAN;
  b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  b.steps = solver.step_count();
  return b;
}

}  // namespace

CaseReport validate_case04(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "04";
  rep.title = "Elastic vertical cut (V1)";
  rep.reference =
      "docs/cases.md Case 4: (a) 9-node FE reference points and exact equilibrium checks; "
      "(b) closed form of the nu = 0 block under sudden gravity";
  const std::string file_a = (fs::path(opt.cases_dir) / "04a_elastic_cut_2d.toml").string();
  const std::string file_b = (fs::path(opt.cases_dir) / "04b_elastic_cut_closed_form_2d.toml").string();

  // (a) at docs/cases.md's dx = 0.5 m and the repeat at 0.25 m (both cheap: run in both modes); full
  // mode adds 0.125 m with every figure reported only (the refinement study of the toe corner).
  const std::vector<double> spacings_a =
      opt.full ? std::vector<double>{0.5, 0.25, 0.125} : std::vector<double>{0.5, 0.25};
  std::vector<double> toe_dx, toe_rows, face_rms;  // per spacing, for the refinement checks
  for (double dx : spacings_a) {
    const CaseA a = run_a(file_a, dx, dir, rep.notes);
    const std::size_t first_metric = rep.metrics.size();
    const std::string tag = fmt::format("(a) dx = {} m: ", dx);
    rep.metrics.push_back(metric(tag + "control-point stress error, max over 5 points x 3 components / rho g H",
                                 a.stress_err, "<=", 0.05, ""));
    Metric disp = metric(tag + "displacement error (settlements, face u_x), max relative", a.disp_err, "<=", 0.05, "");
    if (!disp.pass() && a.crest_err_relaxed <= 0.05) {
      disp.known_deviation = fmt::format(
          "the crest u_x does not stay put: after the relaxation it drifts at {:.2g} m/s, driven by the steady flow at "
          "the toe (method-notes §0.3 item 8, a forced nodal checkerboard whose kinetic energy scales as 1/eps^2 with "
          "the "
          "filter strength); at t = 1.2 s, just relaxed, its error is {:.1f} %, inside 5 %",
          a.crest_drift, 100.0 * a.crest_err_relaxed);
    }
    rep.metrics.push_back(disp);
    rep.metrics.push_back(
        metric(tag + "crest u_x drift over the last 0.5 s (steady toe flow)", a.crest_drift, "", 0.0, "m/s"));
    rep.metrics.push_back(
        metric(tag + "section resultant error, max over node rows y < H, relative", a.section_err, "<=", 0.01, ""));
    // docs/cases.md Case 4(a), restated: the face residual below 2 % of rho g H outside the toe
    // zone y < 0.1 H (the toe is a singular corner, where no discretisation can meet it).
    rep.metrics.push_back(
        metric(tag + "traction residual on the face outside the toe zone, max for y >= 0.1 H (stress points "
                     "extrapolated) / rho g H",
               a.face_res_above, "<=", 0.02, ""));
    rep.metrics.push_back(
        metric(tag + "traction residual on the face, pointwise over the whole face / rho g H (the criterion before "
                     "cases.md restated it: its maximum is in the toe row and grows as dx^(lambda - 1); reported)",
               a.face_res, "", 0.0, ""));
    rep.metrics.push_back(
        metric(tag + "traction residual on the face for y >= 2 dx (all but the two toe rows) / rho g H", a.face_res_2dx,
               "", 0.0, ""));
    rep.metrics.push_back(
        metric(tag + "traction residual on the face, RMS over the rows of sqrt(s_n^2 + s_t^2) / rho g H", a.face_rms,
               "", 0.0, ""));
    rep.metrics.push_back(
        metric(tag + "traction residual on the face in the toe row y = dx/2 / rho g H", a.face_toe_row, "", 0.0, ""));
    rep.metrics.push_back(
        metric(tag + fmt::format("toe-row residual x dx^(1 - lambda), lambda = {} / rho g H", kToeWilliamsLambda),
               a.face_toe_row * std::pow(dx, 1.0 - kToeWilliamsLambda), "", 0.0, "m^0.289"));
    toe_dx.push_back(dx);
    toe_rows.push_back(a.face_toe_row);
    face_rms.push_back(a.face_rms);
    rep.metrics.push_back(
        metric(tag + "traction residual on the top (stress points extrapolated) / rho g H", a.top_res, "<=", 0.02, ""));
    rep.metrics.push_back(metric(tag + "kinetic energy at t = 2 s / its peak (method-notes §0.3 item 8)",
                                 a.ke_peak > 0 ? a.ke_end / a.ke_peak : NAN, "", 0.0, ""));
    rep.notes.push_back(
        fmt::format("(a) dx = {} m: {} steps, {:.1f} s; at t = 2 s kinetic energy {:.3g} J/m (peak "
                    "{:.3g}), largest |v| = {:.3g} m/s at ({}, {}) m",
                    dx, a.steps, a.seconds, a.ke_end, a.ke_peak, a.vmax_end, a.vmax_x, a.vmax_y));
    {
      std::string rows;
      for (std::size_t k = 0; k < std::min<std::size_t>(4, a.face_rows.size()); ++k) {
        const auto& fr = a.face_rows[k];
        rows += fmt::format("{}y = {} m: s_n {:.2f} %, s_t {:.2f} %", k ? "; " : "", fr.y, 100.0 * fr.sn / kGammaH,
                            100.0 * fr.st / kGammaH);
      }
      rep.notes.push_back(
          fmt::format("(a) dx = {} m: face tractions extrapolated from the stress points, toe rows "
                      "(/ rho g H): {} (all rows in a_face_residual_dx{}.csv)",
                      dx, rows, dx));
    }
    if (dx < 0.2) {  // the refinement run: figures reported, nothing judged
      for (std::size_t k = first_metric; k < rep.metrics.size(); ++k) {
        rep.metrics[k].relation.clear();
        rep.metrics[k].known_deviation.clear();
      }
    }
  }
  {
    // docs/cases.md Case 4(a), restated: in the toe zone the toe-row residual x dx^(1 - lambda)
    // within +-15 % of its mean over dx = 0.5 / 0.25 / 0.125 m (the singular field resolved), and
    // the RMS of the residual over the whole face decreasing under refinement.
    const ToeScaling toe = toe_scaling(toe_dx, toe_rows);
    std::string spacings;
    for (std::size_t k = 0; k < toe_dx.size(); ++k) spacings += fmt::format("{}{}", k ? " / " : "", toe_dx[k]);
    const bool all_three = toe_dx.size() >= 3;
    rep.metrics.push_back(metric(
        fmt::format("(a) toe zone: toe-row residual x dx^(1 - lambda), largest departure from its mean over dx = {} m "
                    "(mean {:.4g} rho g H m^0.289){}",
                    spacings, toe.mean, all_three ? "" : "; the criterion is over 0.5 / 0.25 / 0.125 m: --full"),
        toe.max_deviation, all_three ? "<=" : "", 0.15, ""));
    double rms_ratio = NAN;
    std::string rms_text;
    for (std::size_t k = 0; k < face_rms.size(); ++k) {
      rms_text += fmt::format("{}{:.3g} %", k ? " / " : "", 100.0 * face_rms[k]);
      if (k > 0) {
        const double r = face_rms[k] / face_rms[k - 1];
        rms_ratio = std::isnan(rms_ratio) ? r : std::max(rms_ratio, r);
      }
    }
    // "Must decrease": every ratio strictly below 1.
    rep.metrics.push_back(metric(fmt::format("(a) RMS face residual under refinement, largest ratio RMS(dx/2) / "
                                             "RMS(dx) over dx = {} m (RMS {} of rho g H; must decrease)",
                                             spacings, rms_text),
                                 rms_ratio, "<=", std::nextafter(1.0, 0.0), ""));
  }
  rep.notes.push_back(
      "(a) face residual: cases.md restated the criterion (2 % of rho g H outside the toe zone y < 0.1 H; in the toe "
      "zone the toe-row residual x dx^(1 - lambda) within +-15 % of its mean over dx = 0.5 / 0.25 / 0.125 m, and the "
      "RMS over the face decreasing), since the toe is a clamped-free right-angled wedge whose stresses grow as "
      "r^(lambda - 1), lambda = 0.7112 (scripts/williams_corner.py): the pointwise whole-face maximum, kept as a "
      "reported figure, must grow as dx^(lambda - 1) in any discretisation");
  rep.notes.push_back(
      "(a) particles do not move in V1, so the tensile-instability clumping at the top corner "
      "cannot occur (method-notes §0.3 item 6); the stress at the crest node is in a_final_dx*.csv");

  // (b) over two periods at 0.5, 0.25 and the acceptance resolution 0.125 m.
  std::map<double, std::vector<double>> base_centre_2d;  // per spacing, for the 3D run below
  for (double dx : {0.5, 0.25, 0.125}) {
    const CaseB b = run_b<2>(file_b, dx, dir);
    base_centre_2d[dx] = b.base_centre;
    const bool accept = dx < 0.2;
    const std::string tag = fmt::format("(b) dx = {} m: ", dx);
    rep.metrics.push_back(metric(tag + "base sigma_yy error / (2 rho g H), max over x = 1, 5, 9.75 m and t (±2 steps "
                                       "of the reversals excluded)",
                                 b.base_err, accept ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + "top u_y error / (rho g H^2/E), max over x = 1, 5, 9.75 m and t", b.top_err,
                                 accept ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + "spurious face u_x / max|u_y|", b.ux_ratio, accept ? "<=" : "", 0.02, ""));
    rep.metrics.push_back(metric(tag + "sigma_yy spread across x at y = 0, 2.5, 5, 7.5 m / rho g H", b.uniformity,
                                 accept ? "<=" : "", 0.03, ""));
    rep.notes.push_back(
        fmt::format("(b) dx = {} m: {} steps, {:.1f} s{}", dx, b.steps, b.seconds,
                    dx > 0.4 ? " (x = 9.75 m is not a node at this spacing: the nearest node is used)" : ""));
  }
  // (b) in 3D (04b_elastic_cut_closed_form_3d.toml): the same closed form, and the same history
  // as the 2D block at the same spacing (same step, same fibres) to a fraction of a per cent.
  // Quick: 0.5 and 0.25 m (7 s); full: also the acceptance resolution 0.125 m (531 441 nodes, 144 s on
  // two threads).
  const std::string file_b3 = (fs::path(opt.cases_dir) / "04b_elastic_cut_closed_form_3d.toml").string();
  const std::vector<double> spacings_b3 =
      opt.full ? std::vector<double>{0.5, 0.25, 0.125} : std::vector<double>{0.5, 0.25};
  for (double dx : spacings_b3) {
    const CaseB b = run_b<3>(file_b3, dx, dir);
    const bool accept = dx < 0.2;
    const std::string tag = fmt::format("(b) in 3D, dx = {} m: ", dx);
    double to_2d = NAN;
    const auto& h2 = base_centre_2d[dx];
    if (h2.size() == b.base_centre.size() && !h2.empty()) {
      to_2d = 0.0;
      for (std::size_t n = 0; n < h2.size(); ++n)
        to_2d = std::max(to_2d, std::abs(b.base_centre[n] - h2[n]) / (2.0 * kGammaH));
    }
    rep.metrics.push_back(metric(tag + "base sigma_zz at the centre against the 2D block's sigma_yy at x = 5 m, max "
                                       "over t / (2 rho g H)",
                                 to_2d, "<=", 0.01, ""));
    rep.metrics.push_back(metric(tag + "base sigma_zz error / (2 rho g H), max over (1, 1), (5, 5), (9.75, 9.75) m "
                                       "and t (±2 steps of the reversals excluded)",
                                 b.base_err, accept ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + "top u_z error / (rho g H^2/E), max over the three points and t", b.top_err,
                                 accept ? "<=" : "", 0.03, ""));
    rep.metrics.push_back(metric(tag + "spurious u normal to the free faces x = W, y = W / max|u_z|", b.ux_ratio,
                                 accept ? "<=" : "", 0.02, ""));
    rep.metrics.push_back(metric(tag + "sigma_zz spread over the planes z = 0, 2.5, 5, 7.5 m / rho g H", b.uniformity,
                                 accept ? "<=" : "", 0.03, ""));
    rep.notes.push_back(fmt::format("(b) in 3D, dx = {} m: {} steps, {:.1f} s", dx, b.steps, b.seconds));
  }
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case04.py", dir, note)) {
      for (const char* p : {"case04/a_stress_profiles.png", "case04/a_sections.png", "case04/a_deformed.png",
                            "case04/b_base_stress.png", "case04/b_top_uy.png", "case04/b_face_ux.png",
                            "case04/a_face_residual.png", "case04/b3d_base_stress.png"}) {
        rep.plots.push_back(p);
      }
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
