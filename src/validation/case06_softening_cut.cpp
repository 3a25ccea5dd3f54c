// Thesis case 6: viscoplastic vertical cut with softening (docs/cases.md Case 6): N0 = 2.2 must stand
// and N0 = 3.9 collapse at both resolutions; the band is narrower than the plastic zone of
// case 5 at N = 4.2, its width at mid-height changes by less than 25 % when dx is halved, and
// it starts at the toe.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "validation/cut_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {
constexpr double kH = 10.0, kW = 20.0, kGamma = 2000.0 * 9.81;

// The --set overrides of a softening run at N0 = gamma H / c0 (docs/cases.md Case 6).
std::vector<std::string> strength(double n0, double dx) {
  const double c0 = kGamma * kH / n0, y0 = std::sqrt(3.0) * c0;
  return {fmt::format("geometry.spacing={}", dx), "output.interval=0", fmt::format("material.cohesion={:.6g}", c0),
          fmt::format("material.hardening_modulus={:.8g}", -0.4 * y0 / 0.05),
          fmt::format("material.residual_yield_stress={:.8g}", 0.6 * y0)};
}

// Width (FWHM) of eps_vp_eq across the band at mid-height of the cut.
double band_width(const CutSnapshot& s, double dx, const std::string& csv) {
  std::vector<double> xs, es;
  row_profile(s, s.eps, 0.5 * kH, dx, xs, es);
  std::ofstream f(csv);
  f << "x,eps_vp_eq\n";
  for (std::size_t k = 0; k < xs.size(); ++k) f << fmt::format("{},{:.8g}\n", xs[k], es[k]);
  double px = 0.0;
  return fwhm(xs, es, kW - 1.2 * kH, kW - 2.0 * dx, px);
}
}  // namespace

CaseReport validate_case06(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "06";
  rep.title = "Viscoplastic vertical cut with softening (V1)";
  rep.reference =
      "docs/cases.md Case 6: strength between residual and peak: N0 = 2.2 must stand (residual limit "
      "2.27), N0 = 3.9 must collapse (peak limit 3.78); band-width objectivity";
  const std::string file = (fs::path(opt.cases_dir) / "06_softening_cut_2d.toml").string();
  const std::string file5 = (fs::path(opt.cases_dir) / "05_viscoplastic_cut_2d.toml").string();
  const std::vector<double> spacings = opt.full ? std::vector<double>{0.25, 0.125} : std::vector<double>{0.5, 0.25};
  std::vector<double> widths;
  for (double dx : spacings) {
    const bool first = dx == spacings.front();
    // --quick: all three runs at 0.5 m, the collapse run also at 0.25 m for the band width.
    const bool all = opt.full || first;
    const std::string tag = fmt::format("dx = {} m: ", dx);
    if (all) {
      const CutRun s22 = run_cut(file, strength(2.2, dx), 0.01, 0.1);
      rep.metrics.push_back(outcome_metric(tag + "N0 = 2.2 classified stable", s22, CutOutcome::stable));
      rep.notes.push_back(run_note("N0 = 2.2", s22));
      write_history_csv((fs::path(dir) / fmt::format("history_N2.2_dx{}.csv", dx)).string(), s22);
      const CutRun s34 = run_cut(file, strength(3.4, dx), 0.01, 0.1);
      rep.metrics.push_back(metric(tag + "N0 = 3.4 outcome (0 stable, 1 collapse, 2 undecided; not predicted)",
                                   outcome_value(s34.classification.outcome), "", 0.0, ""));
      rep.notes.push_back(run_note("N0 = 3.4", s34));
      write_history_csv((fs::path(dir) / fmt::format("history_N3.4_dx{}.csv", dx)).string(), s34);
    }
    const CutRun s39 = run_cut(file, strength(3.9, dx), 0.01, 0.1);
    rep.metrics.push_back(outcome_metric(tag + "N0 = 3.9 classified collapse", s39, CutOutcome::collapse));
    rep.notes.push_back(run_note("N0 = 3.9", s39));
    write_history_csv((fs::path(dir) / fmt::format("history_N3.9_dx{}.csv", dx)).string(), s39);
    write_snapshot_csv((fs::path(dir) / fmt::format("final_N3.9_dx{}.csv", dx)).string(), s39.final_state);
    // Widths are compared at the same crest displacement, when u_c first exceeds 0.05 H (the
    // runs end with different displacements; the end state is used if it never does).
    const CutSnapshot& w39 = s39.has_collapse_state ? s39.at_collapse : s39.final_state;
    const double w = band_width(w39, dx, (fs::path(dir) / fmt::format("profile_N3.9_dx{}.csv", dx)).string());
    widths.push_back(w);
    rep.metrics.push_back(metric(
        tag + "N0 = 3.9: band width (FWHM of eps_vp_eq along y = H/2 when u_c first exceeds 0.05 H)", w, "", 0.0, "m"));
    rep.metrics.push_back(metric(tag + "N0 = 3.9: distance of the band (eps_vp_eq >= 50 % of max) from the toe",
                                 band_distance_to(s39.final_state, kW, 0.0, 0.0), "<=", 3.0 * dx, "m"));
    if (first) {
      // Case 5 at N = 4.2, same dx (cached if case 5 ran in this process).
      const CutRun c5 = run_cut(
          file5, {fmt::format("geometry.spacing={}", dx), "output.interval=0", "material.cohesion=46710"}, 0.01, 0.1);
      write_history_csv((fs::path(dir) / fmt::format("history_case5_N3.4_dx{}.csv", dx)).string(),
                        run_cut(file5, {fmt::format("geometry.spacing={}", dx), "output.interval=0"}, 0.01, 0.1));
      const double w5 = band_width(c5.has_collapse_state ? c5.at_collapse : c5.final_state, dx,
                                   (fs::path(dir) / fmt::format("profile_case5_N4.2_dx{}.csv", dx)).string());
      rep.metrics.push_back(metric(tag + "band width N0 = 3.9 / plastic-zone width of case 5 N = 4.2 (narrower: < 1)",
                                   w / w5, "<=", 1.0, ""));
    }
  }
  if (widths.size() == 2) {
    rep.metrics.push_back(
        metric(fmt::format("band width change when dx is halved ({} -> {} m), relative", spacings[0], spacings[1]),
               std::abs(widths[1] - widths[0]) / widths[0], "<=", 0.25, ""));
  }
  if (!opt.full) {
    rep.notes.push_back(
        "quick mode: the three runs at dx = 0.5 m and N0 = 3.9 also at 0.25 m; --full runs docs/cases.md's "
        "0.25 m and 0.125 m");
  }
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case06.py", dir, note)) {
      for (const char* p : {"case06/histories.png", "case06/eps_maps.png", "case06/band_profiles.png"}) {
        rep.plots.push_back(p);
      }
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
