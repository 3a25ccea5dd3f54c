// Thesis case 5: viscoplastic vertical cut without softening (docs/cases.md Case 5): N = 3.4 must
// stand and N = 4.2 collapse (docs/cases.md §1.3 classification), and the failure surface of the
// collapse must pass by the toe and emerge on the top 0.7H-1.15H behind the crest.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "validation/cut_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

/// Emergence of the failure surface on the top, m behind the crest: position of the largest
/// eps_vp_eq on the top row away from the crest region (x <= W - 0.3 H).
double emergence_behind_crest(const CutSnapshot& s, double dx, double W, double H) {
  std::vector<double> xs, es;
  row_profile(s, s.eps, H, dx, xs, es);
  double best = -1.0, xb = NAN;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    if (xs[k] <= W - 0.3 * H && es[k] > best) {
      best = es[k];
      xb = xs[k];
    }
  }
  return W - xb;
}

CaseReport validate_case05(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "05";
  rep.title = "Viscoplastic vertical cut without softening (V1)";
  rep.reference =
      "docs/cases.md Case 5: limit analysis of a vertical cut in a Tresca material, N_c = gamma H/c ~ 3.78 "
      "(bracket 2.83-4.00); circular mechanism emerging 0.91H behind the crest";
  const std::string file = (fs::path(opt.cases_dir) / "05_viscoplastic_cut_2d.toml").string();
  const std::vector<double> spacings = opt.full ? std::vector<double>{0.25, 0.125} : std::vector<double>{0.5};
  constexpr double kH = 10.0, kW = 20.0;
  for (double dx : spacings) {
    const std::string sp = fmt::format("geometry.spacing={}", dx);
    const CutRun stable = run_cut(file, {sp, "output.interval=0"}, 0.01, 0.1);
    const CutRun collapse = run_cut(file, {sp, "output.interval=0", "material.cohesion=46710"}, 0.01, 0.1);
    const std::string tag = fmt::format("dx = {} m: ", dx);
    rep.metrics.push_back(outcome_metric(tag + "N = 3.4 classified stable", stable, CutOutcome::stable));
    rep.metrics.push_back(outcome_metric(tag + "N = 4.2 classified collapse", collapse, CutOutcome::collapse));
    rep.notes.push_back(run_note("N = 3.4", stable));
    rep.notes.push_back(run_note("N = 4.2", collapse));
    write_history_csv((fs::path(dir) / fmt::format("history_N3.4_dx{}.csv", dx)).string(), stable);
    write_history_csv((fs::path(dir) / fmt::format("history_N4.2_dx{}.csv", dx)).string(), collapse);
    if (dx == spacings.front()) {
      const CutSnapshot& s = collapse.final_state;
      write_snapshot_csv((fs::path(dir) / "final_N4.2.csv").string(), s);
      write_snapshot_csv((fs::path(dir) / "final_N3.4.csv").string(), stable.final_state);
      if (collapse.has_onset) write_snapshot_csv((fs::path(dir) / "onset_N4.2.csv").string(), collapse.onset);
      const double toe = band_distance_to(s, kW, 0.0, 0.0);
      const double emerge = emergence_behind_crest(s, dx, kW, kH);
      rep.metrics.push_back(metric(tag + "N = 4.2: distance of the failure surface (eps_vp_eq >= 50 % of max) from "
                                         "the toe",
                                   toe, "<=", 3.0 * dx, "m"));
      rep.metrics.push_back(
          metric(tag + "N = 4.2: emergence on the top behind the crest, >= 0.7 H", emerge, ">=", 0.7 * kH, "m"));
      rep.metrics.push_back(
          metric(tag + "N = 4.2: emergence on the top behind the crest, <= 1.15 H", emerge, "<=", 1.15 * kH, "m"));
      std::ofstream(fs::path(dir) / "meta.csv") << "dx,H,W,emergence\n"
                                                << fmt::format("{},{},{},{}\n", dx, kH, kW, emerge);
    }
  }
  if (!opt.full)
    rep.notes.push_back("quick mode: dx = 0.5 m; --full runs docs/cases.md's 0.25 m and the refinement 0.125 m");
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case05.py", dir, note)) {
      for (const char* p : {"case05/histories.png", "case05/eps_N4.2.png", "case05/velocity_onset_N4.2.png"}) {
        rep.plots.push_back(p);
      }
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
