// Case 18 (docs/cases.md, beyond the thesis): the collapse of a frictional, nearly cohesionless
// column of aspect ratio 0.5 (the aluminium-rod experiment of Bui et al. 2008), V2. At rest the
// free surface of a cohesionless deposit is nowhere steeper than the friction angle; the column's
// top near the wall is not disturbed (truncated regime); the run-out L_inf ~ 1.6 L0 (Lube et al.
// 2005); the failure line leaves the toe at Rankine's 45 + phi/2 degrees.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "io/runout.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"
#include "validation/band_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kL0 = 0.2, kH0 = 0.1, kBaseEnd = 1.0;
constexpr double kPhiDegrees = 19.8;
constexpr double kRecordEvery = 0.005;     // s
constexpr double kStopRatio = 1e-4;        // kinetic energy / its peak
constexpr double kFrontWindow = 0.1;       // s: the front must have moved less than dx/10 over it
constexpr double kFailureTime = 0.1;       // s: the failure line read at this time
constexpr double kFailureStrain = 0.02;    // eps_vp_eq that marks the failing wedge
constexpr double kSnapTimes[3] = {0.1, 0.2, 0.4};
constexpr double kAlpha = 1.5;             // alpha-shape disk radius / dx

struct Record {
  double t = 0.0, ke = 0.0, front = 0.0;
};

struct Frame {
  double t = 0.0;
  std::vector<double> x, y, eps, flagged, visual, contact;
};

struct ColumnRun {
  double dx = 0.0;
  std::vector<Record> records;
  std::vector<Frame> frames;
  io::DepositProfile profile;
  double t_end = 0.0, peak_ke = 0.0, t_peak = 0.0, ke_end_ratio = NAN, front_speed = NAN;
  bool settled = false;
  std::string stopped;
  double mass_change = 0.0;
  long behind_bodies = 0;
  long compared = 0, visual = 0, flagged = 0, missed = 0, wrong = 0;
  double steepest = 0.0, steepest_x = NAN;  // |dh/dx| over +-2 dx windows, in the region judged
  double top_min = NAN;                      // the lowest top within 0.3 L0 of the wall
  double failure_angle = NAN;                // degrees, the failing wedge's boundary at 0.1 s
  long steps = 0;
  double seconds = 0.0;
};

// The failure line at kFailureTime: for each band of current height, the leftmost node whose
// eps_vp_eq exceeds kFailureStrain (the wedge's inner boundary); a least-squares line x(y) over
// the bands between 0.1 H0 and 0.8 H0; the angle of that line with the horizontal.
double failure_angle(const Frame& f, double dx) {
  const double band = 2.0 * dx;
  std::vector<double> ys, xs;
  for (double y0 = 0.1 * kH0; y0 < 0.8 * kH0; y0 += band) {
    double left = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < f.x.size(); ++i) {
      if (f.y[i] >= y0 && f.y[i] < y0 + band && f.eps[i] > kFailureStrain) left = std::min(left, f.x[i]);
    }
    if (std::isfinite(left)) {
      ys.push_back(y0 + 0.5 * band);
      xs.push_back(left);
    }
  }
  if (ys.size() < 3) return NAN;
  double my = 0.0, mx = 0.0;
  for (std::size_t k = 0; k < ys.size(); ++k) my += ys[k], mx += xs[k];
  my /= static_cast<double>(ys.size());
  mx /= static_cast<double>(ys.size());
  double syy = 0.0, sxy = 0.0;
  for (std::size_t k = 0; k < ys.size(); ++k) syy += (ys[k] - my) * (ys[k] - my), sxy += (ys[k] - my) * (xs[k] - mx);
  const double dxdy = sxy / syy;  // the line leans back from the toe: x falls as y rises
  return std::atan2(1.0, std::abs(dxdy)) * 180.0 / std::numbers::pi;
}

ColumnRun run_column(const std::string& case_file, double dx) {
  const CaseDocument doc = load_case_document(case_file, {fmt::format("geometry.spacing={}", dx), "output.times=[]"});
  Simulation<2> s(read_case<2>(doc));
  ColumnRun out;
  out.dx = dx;
  const auto t0 = std::chrono::steady_clock::now();
  const auto& nodes = s.nodes();
  const auto& sps = s.stress_points();
  const auto nn = static_cast<std::size_t>(nodes.size());
  const double t_max = s.setup().end_time;
  const double m0 = s.total_mass();
  const auto* enforce = s.scheme().find<ContactEnforce>();
  if (enforce == nullptr) throw InputError("case 18 needs the rigid base and wall ([[body]] entries)");
  const HistoryView eps = node_history(s, "eps_vp_eq", "case 18");
  const Field<double, 1> surface = nodes.template find<double, 1>("free_surface");
  const double tol = 1e-6 * dx;
  auto behind = [&](const Vec<2>& p) { return (p[1] < -tol && p[0] >= 0.0 && p[0] <= kBaseEnd) || p[0] < -tol; };
  auto solid = [](const Vec<2>& p) { return p[1] < 0.0 || p[0] < 0.0; };
  auto frame = [&](bool with_visual) {
    Frame f;
    f.t = s.time();
    const auto& in_contact = enforce->contact().in_contact();
    std::vector<char> vis;
    if (with_visual) vis = io::alpha_boundary(nodes.position, kAlpha * dx, solid);
    for (std::size_t i = 0; i < nn; ++i) {
      f.x.push_back(nodes.position[i][0]);
      f.y.push_back(nodes.position[i][1]);
      f.eps.push_back(eps(i));
      f.flagged.push_back(nodes.view(surface)(i, 0));
      f.visual.push_back(with_visual ? static_cast<double>(vis[i]) : NAN);
      f.contact.push_back(in_contact.empty() ? 0.0 : static_cast<double>(in_contact[i] != 0));
    }
    return f;
  };
  auto record = [&] {
    Record r;
    r.t = s.time();
    const auto v = s.node_velocity();
    for (std::size_t i = 0; i < nn; ++i) {
      r.ke += 0.5 * nodes.mass(static_cast<Index>(i)) * (v(i, 0) * v(i, 0) + v(i, 1) * v(i, 1));
    }
    r.front = io::deposit_profile(nodes.position, 0.0, kBaseEnd, dx).front;
    out.records.push_back(r);
    for (std::size_t i = 0; i < nn; ++i) out.behind_bodies += behind(nodes.position[i]) ? 1 : 0;
    for (Index e = 0; e < sps.size(); ++e) out.behind_bodies += behind(sps.position[static_cast<std::size_t>(e)]) ? 1 : 0;
    out.mass_change = std::max(out.mass_change, std::abs(s.total_mass() / m0 - 1.0));
    if (r.ke > out.peak_ke) out.peak_ke = r.ke, out.t_peak = r.t;
    return r;
  };
  // The front's speed over the last kFrontWindow of records, m/s.
  auto front_speed = [&]() -> double {
    const Record& last = out.records.back();
    for (auto it = out.records.rbegin(); it != out.records.rend(); ++it) {
      if (it->t <= last.t - kFrontWindow + 1e-9) return std::abs(last.front - it->front) / (last.t - it->t);
    }
    return NAN;
  };
  record();
  std::size_t next_snap = 0;
  const long every = std::max(1L, std::lround(kRecordEvery / s.dt()));
  try {
    while (s.time() < t_max - 1e-9) {
      s.step();
      if (next_snap < 3 && s.time() >= kSnapTimes[next_snap] - 0.5 * s.dt()) {
        out.frames.push_back(frame(false));
        if (next_snap == 0) out.failure_angle = failure_angle(out.frames.back(), dx);
        ++next_snap;
      }
      if (s.step_count() % every != 0) continue;
      const Record r = record();
      // At rest: the kinetic energy below 1e-4 of its peak and the front moved less than dx/10
      // over the last 0.1 s.
      const double speed = front_speed();
      if (r.t > out.t_peak + kFrontWindow && r.ke < kStopRatio * out.peak_ke && std::isfinite(speed) &&
          speed * kFrontWindow < 0.1 * dx) {
        out.settled = true;
        break;
      }
    }
  } catch (const SolverError& e) {
    out.stopped = e.what();
  }
  if (out.records.back().t < s.time()) record();
  out.t_end = s.time();
  out.ke_end_ratio = out.records.back().ke / out.peak_ke;
  out.front_speed = front_speed();
  out.frames.push_back(frame(true));
  // The detected free surface against the alpha-shape boundary, nodes not in contact.
  const Frame& f = out.frames.back();
  for (std::size_t i = 0; i < nn; ++i) {
    if (f.contact[i] != 0.0) continue;
    ++out.compared;
    const bool vis = f.visual[i] != 0.0, flag = f.flagged[i] != 0.0;
    out.visual += vis ? 1 : 0;
    out.flagged += flag ? 1 : 0;
    out.missed += vis && !flag ? 1 : 0;
    out.wrong += flag && !vis ? 1 : 0;
  }
  // The deposit: its slope by least squares over +-2 dx, where it is thicker than 3 dx and more
  // than 3 dx from the wall and the front; the top near the wall.
  out.profile = io::deposit_profile(nodes.position, 0.0, kBaseEnd, dx);
  const io::DepositProfile& p = out.profile;
  for (std::size_t k = 0; k < p.h.size() && static_cast<long>(k) <= p.front_column; ++k) {
    const double x = p.centre(k);
    if (x < 0.3 * kL0) out.top_min = std::isfinite(out.top_min) ? std::min(out.top_min, p.h[k]) : p.h[k];
    if (p.h[k] <= 3.0 * dx || x < 3.0 * dx || x > p.front - 3.0 * dx) continue;
    const double slope = io::profile_slope(p, k, 2.0 * dx);
    if (std::isfinite(slope) && std::abs(slope) > out.steepest) out.steepest = std::abs(slope), out.steepest_x = x;
  }
  out.steps = s.step_count();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void write_outputs(const std::string& dir, const ColumnRun& r, const std::string& suffix) {
  {
    std::ofstream f(dir + "/history" + suffix + ".csv");
    f << "t,kinetic,front\n";
    for (const Record& x : r.records) f << fmt::format("{:.6g},{:.8g},{:.6g}\n", x.t, x.ke, x.front);
  }
  {
    std::ofstream f(dir + "/frames" + suffix + ".csv");
    f << "t,x,y,eps_vp_eq,free_surface,visual_boundary,contact\n";
    for (const Frame& m : r.frames) {
      for (std::size_t i = 0; i < m.x.size(); ++i) {
        f << fmt::format("{:.6g},{:.8g},{:.8g},{:.6g},{:g},{:g},{:g}\n", m.t, m.x[i], m.y[i], m.eps[i], m.flagged[i],
                         m.visual[i], m.contact[i]);
      }
    }
  }
  {
    std::ofstream f(dir + "/profile" + suffix + ".csv");
    f << "x,h,count\n";
    for (std::size_t k = 0; k < r.profile.h.size(); ++k) {
      f << fmt::format("{:.6g},{:.6g},{}\n", r.profile.centre(k), r.profile.h[k], r.profile.count[k]);
    }
  }
}

}  // namespace

CaseReport validate_case18(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "18";
  rep.title = "Frictional column collapse, aspect ratio 0.5 (V2, beyond the thesis)";
  const double tan_limit = std::tan((kPhiDegrees + 3.0) * std::numbers::pi / 180.0);
  rep.reference = fmt::format(
      "at rest: surface slope <= tan(phi + 3 deg) = {:.3f}; top within 0.3 L0 of the wall undisturbed; L_inf/L0 in "
      "[1.45, 1.75] (Lube et al. 2005: dL/L0 ~ 1.2 a); failure line at the toe 55 +- 8 deg (Rankine, 45 + phi/2); "
      "docs/cases.md Case 18",
      tan_limit);
  const std::string case_file = (fs::path(opt.cases_dir) / "18_granular_column_2d.toml").string();
  const double coarse = opt.full ? kH0 / 40.0 : kH0 / 20.0;
  const double fine = 0.5 * coarse;
  std::vector<ColumnRun> runs;
  for (const double dx : {coarse, fine}) {
    runs.push_back(run_column(case_file, dx));
    write_outputs(dir, runs.back(), fmt::format("_dx{:g}mm", dx * 1e3));
  }
  // Why a criterion is missed (docs/VALIDATION.md, Case 18): the diagnosis, not a tolerance.
  const std::string nose =
      "open: the deposit is steeper than phi only at its nose (the last 2-4 dx behind the front, where the flow "
      "stopped as a rounded lobe); behind it the surface is flatter than tan(phi)";
  const std::string slump =
      "open: the column does not keep an undisturbed block at the wall: its upper layer yields from the start "
      "(eps_vp_eq 0.1-0.3 near the top at 0.1 s) and the whole surface slumps into one curve, the top near the wall "
      "8-9 % below H0; the failing zone at 0.1 s is a broad fan, not a band from the toe";
  const std::string flags =
      "open: nodes one row inside the deposit's surface are flagged as well (free-surface detection on a sheared, "
      "disordered set, method-notes §3.6); none of the alpha-shape boundary is missed";
  auto push = [&](Metric m, const std::string& why) {
    if (!m.pass()) m.known_deviation = why;
    rep.metrics.push_back(std::move(m));
  };
  for (const ColumnRun& r : runs) {
    const std::string tag = fmt::format("dx = H0/{:.0f}: ", kH0 / r.dx);
    push(metric(tag + "steepest surface slope at rest |dh/dx| (+-2 dx, h > 3 dx, 3 dx from wall and front)", r.steepest,
                "<=", tan_limit, ""),
         nose);
    rep.metrics.push_back(metric(tag + "  where (x)", r.steepest_x, "", 0.0, "m"));
    push(metric(tag + "lowest top within 0.3 L0 of the wall / H0 (>= 0.97)", r.top_min / kH0, ">=", 0.97, ""), slump);
    rep.metrics.push_back(metric(tag + "run-out L_inf / L0", r.profile.front / kL0, ">=", 1.45, ""));
    rep.metrics.push_back(metric(tag + "run-out L_inf / L0 (upper bound)", r.profile.front / kL0, "<=", 1.75, ""));
    push(metric(tag + "failure line at the toe at 0.1 s (eps_vp_eq > 0.02), degrees from the horizontal",
                std::abs(r.failure_angle - 55.0), "<=", 8.0, "deg from 55"),
         slump);
    rep.metrics.push_back(metric(tag + "  the angle", r.failure_angle, "", 0.0, "deg"));
    rep.metrics.push_back(
        metric(tag + "kinetic energy / its peak at the end", r.ke_end_ratio, "<=", kStopRatio * (1.0 + 1e-9), ""));
    const std::string creep =
        "open: the nose's last particles still creep (a few mm/s) when the kinetic energy has fallen below 1e-4 of "
        "its peak; the run stops at rest only when both hold, so a creeping nose runs it to 2 s";
    push(metric(tag + "front speed over the last 0.1 s", r.front_speed, "<=", 1e-3, "m/s"), creep);
    // At rest means both the energy and the front (docs/cases.md Case 18): when only the front's
    // creep keeps the run going, it is the same deviation as the row above.
    Metric at_rest = metric(tag + "time at rest (<= 2 s)", r.t_end, "<=", 2.0 + 1e-9, "s");
    if (!at_rest.pass() && r.ke_end_ratio <= kStopRatio * (1.0 + 1e-9) && r.front_speed > 1e-3) {
      at_rest.known_deviation = creep;
    }
    rep.metrics.push_back(std::move(at_rest));
    rep.metrics.push_back(metric(tag + "mass change (nodes and stress points)", r.mass_change, "<=", 5e-3, ""));
    rep.metrics.push_back(metric(tag + "particles behind the base or the wall at the records",
                                 static_cast<double>(r.behind_bodies), "<=", 0.0, ""));
    const double share = r.visual > 0 ? static_cast<double>(r.missed + r.wrong) / static_cast<double>(r.visual) : 1.0;
    push(metric(tag + fmt::format("free surface vs the alpha-shape boundary (r = {} dx): (missed + wrong) / boundary "
                                  "nodes ({} boundary, {} flagged, {} missed, {} wrong)",
                                  kAlpha, r.visual, r.flagged, r.missed, r.wrong),
                share, "<=", 0.02, ""),
         flags);
    rep.metrics.push_back(metric(tag + "run completed without the solver stopping", r.stopped.empty() ? 1.0 : 0.0, ">=",
                                 1.0, ""));
    rep.notes.push_back(fmt::format("{}{} steps in {:.1f} s; peak kinetic energy {:.4g} J/m at {:.3f} s; at rest at "
                                    "{:.3f} s{}",
                                    tag, r.steps, r.seconds, r.peak_ke, r.t_peak, r.t_end,
                                    r.stopped.empty() ? "" : "; stopped: " + r.stopped));
  }
  const double change = std::abs(runs[1].profile.front / runs[0].profile.front - 1.0);
  rep.metrics.push_back(metric("run-out change from the coarse to the fine spacing", change, "<=", 0.05, ""));
  if (!opt.full) rep.notes.push_back("quick mode: H0/20 and H0/40; --full runs docs/cases.md's H0/40 and H0/80");
  std::string note;
  if (opt.plots && run_plot_script("plot_case18.py", dir, note)) {
    rep.plots = {"case18/snapshots.png", "case18/profile.png", "case18/history.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
