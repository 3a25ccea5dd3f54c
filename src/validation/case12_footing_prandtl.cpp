// Thesis case 12: bearing capacity of a rigid strip footing on a weightless Tresca soil (Prandtl)
// (docs/cases.md Case 12), V2: the plateau of the footing pressure (the rigid body's reaction)
// against q_u = (2 + pi) c for a smooth and a rough footing at two resolutions, the depth of the
// plastic zone and the extent of the surface heave.
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

constexpr double kB = 2.0, kHalf = 1.0, kDepth = 4.0;  // m: footing width, loaded half-width, layer depth
constexpr double kCohesion = 5.0e4;                    // Pa
constexpr double kQu = (2.0 + std::numbers::pi) * kCohesion;
constexpr double kSpeed = 0.05, kRamp = 0.1;  // m/s, s
constexpr double kCutY = 1.0;                 // m: the cross-check's section, 1.5 B deep (below the plastic zone)
// The maps: settlement/B = 0.03 and 0.06 (the plateau's ends: the heave rate) and 0.05.
constexpr double kMapRatios[3] = {0.03, 0.05, 0.06};

double time_at(double ratio) { return 0.5 * kRamp + ratio * kB / kSpeed; }

struct Measures {
  double plateau = NAN;       // Pa
  double zone_depth = NAN;    // m below the surface: the deepest node flowing over the plateau
  double yield_depth = NAN;   // m: the deepest stress point at q > sigma_Y at 0.05 B
  double heave_extent = NAN;  // m beyond the footing edge: the farthest surface node rising at >= 5 % of v_f
  double heave_max = NAN;     // m, the largest surface heave at 0.05 B
};

Measures measure(const FootingRun& r) {
  Measures m;
  m.plateau = mean_pressure(r, 0.03 * kB, 0.06 * kB);
  if (r.maps.size() < 3) return m;
  const FootingMap& at = r.maps[1];
  // The plastic zone: the nodes that flow over the plateau, their eps_vp_eq growing between
  // settlement/B = 0.03 and 0.06 by at least 0.1 ds/B (ds the settlement over it; the
  // mechanism's own shear is of order ds/B). Its depth: the deepest such node below the surface.
  // (The stress points at q > sigma_Y are also reported: an elastic region at the yield stress
  // counts there, however slowly it flows.)
  const FootingMap &a = r.maps[0], &b = r.maps[2];
  const double ds = b.settlement - a.settlement;
  double ymin = kDepth;
  for (std::size_t i = 0; i < a.X.size(); ++i) {
    if (b.eps[i] - a.eps[i] >= 0.1 * ds / kB) ymin = std::min(ymin, at.y[i]);
  }
  m.zone_depth = kDepth - ymin;
  double yq = kDepth;
  for (std::size_t e = 0; e < at.sx.size(); ++e) {
    if (at.flowing[e] != 0) yq = std::min(yq, at.sy[e]);
  }
  m.yield_depth = kDepth - yq;
  // The heave rate over the plateau: in steady plastic flow the soil outside the mechanism is
  // at rest, so a surface node rising at 5 % of the footing's speed is inside it.
  m.heave_extent = 0.0;
  m.heave_max = 0.0;
  for (std::size_t i = 0; i < a.X.size(); ++i) {
    if (std::abs(a.Y[i] - kDepth) > 1e-9 || a.X[i] <= kHalf + 1e-9) continue;
    if ((b.uy[i] - a.uy[i]) / ds >= 0.05) m.heave_extent = std::max(m.heave_extent, a.X[i] - kHalf);
    m.heave_max = std::max(m.heave_max, at.uy[i]);
  }
  return m;
}

}  // namespace

CaseReport validate_case12(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "12";
  rep.title = "Strip footing bearing capacity, weightless Tresca soil (Prandtl, V2)";
  rep.reference = "q_u = (2 + pi) c = 257.1 kPa for a smooth and a rough footing (docs/cases.md Case 12); plastic "
                  "zone 0.35B (Hill) - 0.71B (Prandtl) deep; heave within B of the footing edge";
  const std::string file = (fs::path(opt.cases_dir) / "12_footing_prandtl_2d.toml").string();
  // Quick: dx = 0.1 m (B/20) to the end of the plateau; full: B/20 and B/40 to 0.1 B.
  const std::vector<double> spacings = opt.full ? std::vector<double>{0.1, 0.05} : std::vector<double>{0.1};
  const double t_end = opt.full ? time_at(0.1) : time_at(0.065);
  std::vector<double> maps;
  for (double r : kMapRatios) maps.push_back(r * kB);
  std::ofstream meta(fs::path(dir) / "runs.csv");
  meta << "contact,dx,file,maps,plateau,zone_depth,heave_extent,heave_max,yield_depth,cut\n";
  for (const char* contact : {"smooth", "rough"}) {
    double err_prev = NAN;
    for (double dx : spacings) {
      const FootingRun r = run_footing(
          file, {fmt::format("geometry.spacing={}", dx), fmt::format("body.0.contact={}", contact)}, t_end, 0.01,
          kHalf, std::sqrt(3.0) * kCohesion, maps, kCutY);
      const std::string stem = fmt::format("{}_dx{}", contact, dx);
      write_footing_records((fs::path(dir) / ("force_" + stem + ".csv")).string(), r);
      write_footing_maps((fs::path(dir) / ("maps_" + stem + ".csv")).string(), r);
      const Measures m = measure(r);
      meta << fmt::format("{},{},{},{},{:.8g},{:.6g},{:.6g},{:.6g},{:.6g},{:.8g}\n", contact, dx, stem, r.maps.size(),
                          m.plateau, m.zone_depth, m.heave_extent, m.heave_max, m.yield_depth,
                          mean_cut_pressure(r, 0.03 * kB, 0.06 * kB));
      const std::string tag = fmt::format("{}, dx = {} m: ", contact, dx);
      rep.metrics.push_back(metric(tag + "time reached / end", r.t_reached / t_end, ">=", 1.0 - 1e-9, ""));
      const double err = m.plateau / kQu - 1.0;
      const double cut = mean_cut_pressure(r, 0.03 * kB, 0.06 * kB) / kQu - 1.0;
      // The smooth footing's contact row: its nodal stress carries an odd-even mode that grows at
      // the footing's edge (docs/VALIDATION.md Case 12); the soil below carries the load of the
      // section cut.
      const std::string smooth_reason = fmt::format(
          "open: the nodal stress of the smooth footing's contact row carries an odd-even mode (sigma_yy "
          "alternating by up to +-100 % of its mean) that grows at the footing's edge from settlement/B ~ 0.045 and "
          "inflates the reaction there; the stress points under the footing are smooth and the section cut 1.5 B "
          "deep gives {:+.1f} % over the same window. The mode's cause in V2's contact row is not established",
          100.0 * cut);
      rep.metrics.push_back(metric(tag + "plateau (settlement/B 0.03-0.06) / (2 + pi) c - 1, lower bound",
                                   std::isfinite(err) ? err : -1.0, ">=", -0.03, ""));
      {
        Metric up = metric(tag + "plateau (settlement/B 0.03-0.06) / (2 + pi) c - 1, upper bound",
                           std::isfinite(err) ? err : 1.0, "<=", 0.08, "");
        if (!up.pass() && std::string(contact) == "smooth" && std::isfinite(err)) up.known_deviation = smooth_reason;
        rep.metrics.push_back(up);
      }
      rep.metrics.push_back(
          metric(tag + "cross-check: section-cut plateau (1.5 B deep) / (2 + pi) c - 1", cut, "", 0.0, ""));
      rep.metrics.push_back(metric(tag + "plastic zone depth (nodes flowing over settlement/B 0.03-0.06), / B",
                                   m.zone_depth / kB, ">=", 0.3, ""));
      {
        Metric z = metric(tag + "plastic zone depth (nodes flowing over settlement/B 0.03-0.06), / B",
                          m.zone_depth / kB, "<=", 0.9, "");
        if (!z.pass() && std::isfinite(m.zone_depth))
          z.known_deviation = fmt::format(
              "open: the flowing zone reaches {:.3f} B, deeper than Prandtl's 0.71 B (plateau {:+.1f} % over (2 + pi) "
              "c). The simple scheme's numerical viscosity widens the mechanism (0.95-1.0 B at w = 1); at w = 0.1 (the "
              "case's setting before the hourglass control became the default) the smooth footing's zone is 0.81 / 0.88 B and the rough one's deepest flowing nodes are the "
              "row at 0.9 B, moved 6-8 mm down (0.903 / 0.904 B at B/20 / B/40), a tail of the Perzyna viscosity's: at "
              "gamma_f = 100 1/s instead of 10 it is 0.855 B (B/20; docs/VALIDATION.md Case 12)",
              m.zone_depth / kB, 100.0 * err);
        rep.metrics.push_back(z);
      }
      rep.metrics.push_back(metric(tag + "deepest stress point at q > sigma_Y at settlement/B = 0.05, / B",
                                   m.yield_depth / kB, "", 0.0, ""));
      {
        Metric h = metric(tag + "heave extent beyond the footing edge (rising at >= 5 % of v_f), / B",
                          m.heave_extent / kB, "<=", 1.2, "");
        if (!h.pass())
          h.known_deviation = fmt::format(
              "open: the surface still rises at 5 % of the footing's speed {:.3f} B from the edge (Prandtl: B): the "
              "mechanism widened by the simple scheme's numerical viscosity, as the plastic-zone depth above (1.15-1.3 "
              "B at w = 1, 1.0-1.175 B at w = 0.1; docs/VALIDATION.md Case 12)",
              m.heave_extent / kB);
        rep.metrics.push_back(h);
      }
      rep.metrics.push_back(metric(tag + "largest surface heave at settlement/B = 0.05", m.heave_max, "", 0.0, "m"));
      rep.metrics.push_back(metric(tag + "nodes and stress points put back on the footing",
                                   r.records.empty() ? 0.0 : static_cast<double>(r.records.back().projections), "",
                                   0.0, ""));
      rep.notes.push_back(fmt::format("{}{} steps in {:.1f} s{}", tag, r.steps, r.seconds,
                                      r.stopped.empty() ? "" : "; stopped: " + r.stopped));
      if (std::isfinite(err_prev)) {
        // The fine run closer to (2 + pi) c than the coarse one, or within 2 % of it.
        const double closer = std::abs(err) < std::abs(err_prev) ? 0.0 : std::abs(err);
        Metric conv = metric(fmt::format("{}: fine plateau error when not closer than the coarse one", contact), closer,
                             "<=", 0.02, "");
        if (!conv.pass() && std::string(contact) == "smooth") conv.known_deviation = smooth_reason;
        if (!conv.pass() && std::string(contact) == "rough")
          conv.known_deviation = fmt::format(
              "open: the rough plateau does not move under refinement ({:+.2f} % at B/20, {:+.2f} % at B/40, both "
              "within -3/+8 %): the excess is not a discretisation error of the spacing; its cause (the viscoplastic "
              "mechanism's width above; the reaction also lies 2-7 % under the section cut) is not established",
              100.0 * err_prev, 100.0 * err);
        rep.metrics.push_back(conv);
      }
      err_prev = err;
    }
  }
  meta.close();
  {
    // Held footing (docs/VALIDATION.md, "A held footing does not keep its load"): the smooth
    // footing at B/20 stopped at 2 s (settlement/B ~ 0.05, on the plateau) over 0.1 s and held
    // 1 s. A rate-independent soil keeps its load; the figures say how much of the moving
    // resistance is the scheme's resistance to motion and how much creeps away.
    const double t_stop = 2.0, hold = 1.0;
    const std::string table = fmt::format("times = [0.0, 0.1, {}, {}], values = [0.0, 1.0, 1.0, 0.0]", t_stop,
                                          t_stop + 0.1);
    const FootingRun h = run_footing(
        file,
        {"geometry.spacing=0.1", "body.0.contact=smooth",
         fmt::format("functions.push={{type = \"table\", {}, scale = -0.05}}", table),
         fmt::format("functions.ramp={{type = \"table\", {}}}", table)},
        t_stop + 0.1 + hold, 0.01, kHalf, std::sqrt(3.0) * kCohesion, {}, kCutY);
    auto mean_between = [&](double t0, double t1) {
      double sum = 0.0;
      int n = 0;
      for (const FootingRecord& r : h.records) {
        if (r.t >= t0 && r.t <= t1) sum += r.pressure, ++n;
      }
      return n > 0 ? sum / n : NAN;
    };
    const double moving = mean_between(t_stop - 0.2, t_stop);
    const double held = mean_between(t_stop + 0.1 + hold - 0.1, t_stop + 0.1 + hold);
    rep.metrics.push_back(metric("smooth, dx = 0.1 m, held footing: q moving (0.2 s before the stop) / (2 + pi) c",
                                 moving / kQu, "", 0.0, ""));
    rep.metrics.push_back(metric("smooth, dx = 0.1 m, held footing: q held 1 s / q moving", held / moving, "", 0.0, ""));
    rep.notes.push_back(fmt::format("held footing: {} steps in {:.1f} s{}", h.steps, h.seconds,
                                    h.stopped.empty() ? "" : "; stopped: " + h.stopped));
  }
  if (!opt.full)
    rep.notes.push_back("quick mode: dx = 0.1 m (B/20) to settlement/B = 0.065; --full runs B/20 and B/40 to 0.1 B");
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case12.py", dir, note)) {
      rep.plots = {"case12/pressure.png", "case12/fields.png", "case12/heave.png"};
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
