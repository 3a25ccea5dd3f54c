// Thesis case 11: a rigid smooth strip footing at the crest of a weightless vertical cut in a
// Tresca soil (docs/cases.md Case 11), V2: the plateau of the footing pressure (the rigid body's
// reaction over B) against the exact q_lim = 2c, and the failure band from the inner footing edge
// to the face (angle, emergence depth, width under refinement).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "validation/footing_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kW = 20.0, kH = 10.0, kB = 5.0;  // m
constexpr double kCohesion = 5.0e4;               // Pa
constexpr double kQlim = 2.0 * kCohesion;
constexpr double kSpeed = 0.05, kRamp = 0.1;  // m/s, s
constexpr double kMapRatios[3] = {0.02, 0.05, 0.1};
constexpr double kCutY = 2.5;  // m: the cross-check's section across the block, 1.5 B deep (below the band)

double time_at(double ratio) { return 0.5 * kRamp + ratio * kB / kSpeed; }

/// The band of docs/cases.md §1.3 in the eps_vp_eq map: the nodes at >= 50 % of the largest
/// value in the band region (reference X >= W - 1.2 B, H - 1.5 B <= Y <= H - 0.1 B: the top
/// 0.1 B, where the footing's inner edge concentrates strain by the boundary, is left out), and
/// the principal axis of that cloud in the current configuration.
struct Band {
  double angle = NAN;      // degrees to the horizontal (magnitude)
  double emergence = NAN;  // m: depth below the top at which the axis meets the face x = W
  double width = NAN;      // m: sqrt(12 lambda_min), the width of a uniform band of that spread
  double start = NAN;      // m: distance of the axis from the inner footing edge (W - B, H)
  int particles = 0;
  std::vector<char> in_band;
};

Band fit(const FootingMap& m) {
  Band b;
  const std::size_t n = m.x.size();
  auto region = [&](std::size_t i) {
    return m.X[i] >= kW - 1.2 * kB && m.Y[i] >= kH - 1.5 * kB && m.Y[i] <= kH - 0.1 * kB;
  };
  double emax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (region(i)) emax = std::max(emax, m.eps[i]);
  }
  b.in_band.assign(n, 0);
  if (emax <= 0.0) return b;
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (region(i) && m.eps[i] >= 0.5 * emax) b.in_band[i] = 1, mx += m.x[i], my += m.y[i], ++b.particles;
  }
  if (b.particles < 3) return b;
  mx /= b.particles;
  my /= b.particles;
  double cxx = 0.0, cyy = 0.0, cxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (b.in_band[i] == 0) continue;
    cxx += (m.x[i] - mx) * (m.x[i] - mx);
    cyy += (m.y[i] - my) * (m.y[i] - my);
    cxy += (m.x[i] - mx) * (m.y[i] - my);
  }
  cxx /= b.particles;
  cyy /= b.particles;
  cxy /= b.particles;
  const double theta = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  b.angle = std::abs(theta) * 180.0 / std::numbers::pi;
  if (b.angle > 90.0) b.angle = 180.0 - b.angle;
  const double mean = 0.5 * (cxx + cyy), dev = std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
  b.width = std::sqrt(12.0 * std::max(mean - dev, 0.0));
  const double tx = std::cos(theta), ty = std::sin(theta);
  if (std::abs(tx) > 1e-12) b.emergence = kH - (my + (kW - mx) * ty / tx);
  b.start = std::abs((kW - kB - mx) * ty - (kH - my) * tx);
  return b;
}

}  // namespace

CaseReport validate_case11(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "11";
  rep.title = "Strip footing at the crest of a weightless vertical cut (V2)";
  rep.reference = "q_lim = 2c = 100 kPa (docs/cases.md Case 11); the band at 45 degrees from the inner footing edge "
                  "(W - B, H) to the face at depth B";
  const std::string file = (fs::path(opt.cases_dir) / "11_footing_on_cut_2d.toml").string();
  // Quick: dx = 0.25 m to settlement/B = 0.055; full: 0.25 and 0.125 m to 0.1 B (and 0.0625 m
  // with --refine: whether the width's change falls with a third level).
  std::vector<double> spacings = opt.full ? std::vector<double>{0.25, 0.125} : std::vector<double>{0.25};
  if (opt.full && opt.refine) spacings.push_back(0.0625);
  const double t_end = opt.full ? time_at(0.1) : time_at(0.055);
  std::vector<double> maps;
  for (double r : kMapRatios) maps.push_back(r * kB);
  std::ofstream meta(fs::path(dir) / "runs.csv");
  meta << "dx,file,maps,plateau,angle,emergence,width,start\n";
  double width_prev = NAN, dx_prev = NAN;
  for (std::size_t level = 0; level < spacings.size(); ++level) {
    const double dx = spacings[level];
    const FootingRun r =
        run_footing(file, {fmt::format("geometry.spacing={}", dx)}, t_end, 0.02, kB, std::sqrt(3.0) * kCohesion, maps, kCutY);
    const std::string stem = fmt::format("dx{}", dx);
    write_footing_records((fs::path(dir) / ("force_" + stem + ".csv")).string(), r);
    write_footing_maps((fs::path(dir) / ("maps_" + stem + ".csv")).string(), r);
    const double plateau = mean_pressure(r, 0.02 * kB, 0.05 * kB);
    Band band;
    if (r.maps.size() >= 2) band = fit(r.maps[1]);  // at settlement/B = 0.05
    {
      std::ofstream f(fs::path(dir) / ("band_" + stem + ".csv"));
      f << "in_band\n";
      for (char c : band.in_band) f << static_cast<int>(c) << "\n";
    }
    meta << fmt::format("{},{},{},{:.8g},{:.6g},{:.6g},{:.6g},{:.6g}\n", dx, stem, r.maps.size(), plateau, band.angle,
                        band.emergence, band.width, band.start);
    const std::string tag = fmt::format("dx = {} m: ", dx);
    const double err = plateau / kQlim - 1.0;
    rep.metrics.push_back(metric(tag + "time reached / end", r.t_reached / t_end, ">=", 1.0 - 1e-9, ""));
    rep.metrics.push_back(metric(tag + "plateau (settlement/B 0.02-0.05) / 2c - 1, lower bound",
                                 std::isfinite(err) ? err : -1.0, ">=", -0.03, ""));
    const double cut = mean_cut_pressure(r, 0.02 * kB, 0.05 * kB) / kQlim - 1.0;
    {
      Metric up = metric(tag + "plateau (settlement/B 0.02-0.05) / 2c - 1, upper bound",
                         std::isfinite(err) ? err : 1.0, "<=", 0.08, "");
      if (!up.pass() && std::isfinite(err)) {
        up.known_deviation = fmt::format(
            "open: the section cut 1.5 B deep gives {:+.1f} % over the same window. The excess is the simple "
            "scheme's numerical viscosity in the band (method-notes eq. (2.3.2)): +12.6 / +15.2 % at 0.25 / "
            "0.125 m with w = 1, +6.4 / +4.9 % with the case's w = 0.25 and nodal mean stress filter "
            "(docs/VALIDATION.md Case 11)",
            100.0 * cut);
      }
      rep.metrics.push_back(up);
    }
    rep.metrics.push_back(metric(tag + "cross-check: section-cut plateau (1.5 B deep) / 2c - 1", cut, "", 0.0, ""));
    const double dev = std::isfinite(band.angle) ? std::abs(band.angle - 45.0) : 90.0;
    rep.metrics.push_back(metric(tag + "band angle at settlement/B = 0.05, |theta - 45 deg|", dev, "<=", 7.0, "deg"));
    const double emerge = std::isfinite(band.emergence) ? std::abs(band.emergence / kB - 1.0) : 1.0;
    rep.metrics.push_back(metric(tag + "band emergence depth on the face, |depth / B - 1|", emerge, "<=", 0.15, ""));
    rep.metrics.push_back(metric(tag + "band axis distance from the inner footing edge", band.start, "", 0.0, "m"));
    rep.metrics.push_back(metric(tag + "band width (sqrt(12) x the cloud's spread across it)", band.width, "", 0.0,
                                 "m"));
    if (level >= 2 && std::isfinite(width_prev)) {
      // The third level (--refine): reported beside the criterion, which stays on cases.md's pair.
      rep.metrics.push_back(
          metric(fmt::format("band width change from dx = {} to {} m, |w(fine) / w(coarse) - 1|", dx_prev, dx),
                 std::abs(band.width / width_prev - 1.0), "", 0.0, ""));
      rep.metrics.push_back(metric(tag + "band width / dx", band.width / dx, "", 0.0, ""));
    } else if (std::isfinite(width_prev)) {
      Metric change = metric("band width: |w(fine) / w(coarse) - 1| (converges under refinement)",
                             std::abs(band.width / width_prev - 1.0), "<=", 0.25, "");
      // A band in a soil without softening: the exact one is a slip line of no width, and the
      // less the velocity update smooths, the nearer its width comes to following dx.
      if (!change.pass() && std::isfinite(change.value))
        change.known_deviation = fmt::format(
            "open: the band narrows from {:.2f} to {:.2f} m ({:.1f} to {:.1f} dx) when dx halves. Without softening "
            "the exact band is a slip line of no width; the width that changed by 22 % with the simple scheme at full "
            "weight was set by its numerical viscosity, which also held the plateau 13-15 % over 2c; with less of it "
            "the width follows dx more closely (28 % at w = 0.25, 38 % at w = 0.1, before the hourglass control "
            "replaced the simple scheme as the default), and with a third level (--refine: "
            "26.5 % from 0.125 to 0.0625 m) it falls as dx^0.45, towards the slip line, not to a width of its own "
            "(docs/VALIDATION.md Case 11)",
            width_prev, band.width, width_prev / dx_prev, band.width / dx);
      rep.metrics.push_back(change);
    }
    width_prev = band.width;
    dx_prev = dx;
    rep.notes.push_back(fmt::format("{}{} steps in {:.1f} s; {} nodes in the band{}", tag, r.steps, r.seconds,
                                    band.particles, r.stopped.empty() ? "" : "; stopped: " + r.stopped));
  }
  meta.close();
  if (!opt.full)
    rep.notes.push_back("quick mode: dx = 0.25 m to settlement/B = 0.055; --full runs 0.25 and 0.125 m to 0.1 B");
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case11.py", dir, note)) {
      rep.plots = {"case11/pressure.png", "case11/eps_maps.png"};
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
