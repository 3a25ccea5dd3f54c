// Thesis case 10: failure and post-failure of a cohesive vertical cut (docs/cases.md Case 10), V2:
// N = 3.4 must stand with displacements below 1 % of H, N = 4.5 must fail along a band from the
// toe with its main scarp 0.7H-1.15H behind the crest (the circular mechanism emerges at 0.91H,
// the planar wedge at 1.0H), motion must end, the detected free surface must stay on the
// boundary of the cloud, and the mass must be conserved. Reuses Case 5's machinery (cut_common).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "io/runout.hpp"
#include "validation/cut_common.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kW = 20.0, kH = 10.0;
constexpr double kTrackEvery = 0.25;  // s: the scarp, the surface flags and the mass
constexpr double kAlpha = 1.5;        // alpha-shape disk radius / dx (as Case 9)

// The snapshot in the reference configuration (X = x - u), where Case 5's measures of the band
// and of its emergence on the top apply as on the lattice.
CutSnapshot reference(const CutSnapshot& s) {
  CutSnapshot r = s;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    r.x[i] = s.x[i] - s.ux[i];
    r.y[i] = s.y[i] - s.uy[i];
  }
  return r;
}

struct SlopeTrack {
  std::vector<double> t, scarp, mass;
  long interior_flagged_max = 0;  // flagged nodes off the alpha-shape boundary, worst record
  double interior_flagged_t = NAN;
  long interior_flagged_end = 0, flagged_end = 0, boundary_end = 0;
  double mass_change = 0.0;
};

struct Result {
  CutRun run;
  SlopeTrack track;
  double max_disp = 0.0;  // m, largest |u| at the end
  double t_settled = NAN; // s, first time after the peak with KE <= 1e-4 of the peak
  double ke_end_ratio = NAN;
  double scarp_end = NAN, scarp_onset = NAN, toe_distance = NAN;
};

Result run_slope(const std::string& file, double dx, const std::vector<std::string>& extra) {
  Result res;
  SlopeTrack& tr = res.track;
  double next = 0.0, m0 = 0.0;
  auto flags_off_boundary = [&](const Simulation<2>& s, long& flagged, long& boundary) {
    const auto& nodes = s.nodes();
    const Field<double, 1> surface = nodes.template find<double, 1>("free_surface");
    // The cloud's own outline (no body covers it): a face that has separated from the wall
    // by a crack of a few millimetres is a boundary, not the interior.
    const auto vis = io::alpha_boundary(nodes.position, kAlpha * dx);
    long off = 0;
    flagged = boundary = 0;
    for (std::size_t i = 0; i < vis.size(); ++i) {
      const bool f = nodes.view(surface)(i, 0) != 0.0;
      flagged += f ? 1 : 0;
      boundary += vis[i] != 0 ? 1 : 0;
      off += f && vis[i] == 0 ? 1 : 0;
    }
    return off;
  };
  auto mass = [](const Simulation<2>& s) { return s.total_mass(); };
  const StepHook hook = [&](const Simulation<2>& s) {
    if (m0 == 0.0) m0 = mass(s);
    if (s.time() < next - 1e-9) return;
    next += kTrackEvery;
    const CutSnapshot ref = reference(snapshot(s, s.time()));
    tr.t.push_back(s.time());
    tr.scarp.push_back(emergence_behind_crest(ref, dx, kW, kH));
    tr.mass.push_back(mass(s));
    tr.mass_change = std::max(tr.mass_change, std::abs(tr.mass.back() / m0 - 1.0));
    long flagged = 0, boundary = 0;
    const long off = flags_off_boundary(s, flagged, boundary);
    if (off > tr.interior_flagged_max) tr.interior_flagged_max = off, tr.interior_flagged_t = s.time();
    tr.interior_flagged_end = off, tr.flagged_end = flagged, tr.boundary_end = boundary;
  };
  std::vector<std::string> o = {fmt::format("geometry.spacing={}", dx), "output.interval=0"};
  o.insert(o.end(), extra.begin(), extra.end());
  res.run = run_cut(file, o, 0.01, 0.1, hook);
  const CutRun& r = res.run;
  for (std::size_t i = 0; i < r.final_state.x.size(); ++i) {
    res.max_disp = std::max(res.max_disp, std::hypot(r.final_state.ux[i], r.final_state.uy[i]));
  }
  const auto peak = std::max_element(r.ke.begin(), r.ke.end());
  for (auto it = peak; it != r.ke.end(); ++it) {
    if (*it <= 1e-4 * *peak) {
      res.t_settled = r.t[static_cast<std::size_t>(it - r.ke.begin())];
      break;
    }
  }
  res.ke_end_ratio = r.ke.back() / *peak;
  const CutSnapshot end_ref = reference(r.final_state);
  res.scarp_end = emergence_behind_crest(end_ref, dx, kW, kH);
  res.toe_distance = band_distance_to(end_ref, kW, 0.0, 0.0);
  if (r.has_collapse_state) res.scarp_onset = emergence_behind_crest(reference(r.at_collapse), dx, kW, kH);
  return res;
}

void write_track(const std::string& file, const SlopeTrack& t) {
  std::ofstream f(file);
  f << "t,scarp,mass\n";
  for (std::size_t k = 0; k < t.t.size(); ++k) f << fmt::format("{:.6g},{:.6g},{:.12g}\n", t.t[k], t.scarp[k], t.mass[k]);
}

}  // namespace

CaseReport validate_case10(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "10";
  rep.title = "Cohesive vertical slope: failure and post-failure (V2)";
  rep.reference =
      "docs/cases.md Case 10: onset as Case 5 (N_c ~ 3.78); circular toe mechanism emerging 0.91H behind the crest, "
      "planar wedge 1.0H; motion must stop";
  const std::string file = (fs::path(opt.cases_dir) / "10_cohesive_slope_2d.toml").string();
  const double dx = opt.full ? 0.25 : 0.5;
  const std::string tag = fmt::format("dx = {} m: ", dx);
  const Result st = run_slope(file, dx, {});
  const Result fl = run_slope(file, dx, {"material.cohesion=43600"});
  for (const auto& [label, res] : {std::pair<std::string, const Result&>{"N3.4", st}, {"N4.5", fl}}) {
    write_history_csv((fs::path(dir) / fmt::format("history_{}.csv", label)).string(), res.run);
    write_track((fs::path(dir) / fmt::format("track_{}.csv", label)).string(), res.track);
    write_snapshot_csv((fs::path(dir) / fmt::format("final_{}.csv", label)).string(), res.run.final_state);
    if (res.run.has_onset) write_snapshot_csv((fs::path(dir) / fmt::format("onset_{}.csv", label)).string(), res.run.onset);
  }
  std::ofstream(fs::path(dir) / "meta.csv") << "dx,H,W,scarp_end,scarp_onset\n"
                                            << fmt::format("{},{},{},{},{}\n", dx, kH, kW, fl.scarp_end, fl.scarp_onset);

  rep.metrics.push_back(outcome_metric(tag + "N = 3.4 classified stable", st.run, CutOutcome::stable));
  rep.metrics.push_back(metric(tag + "N = 3.4: largest displacement at the end / H", st.max_disp / kH, "<=", 0.01, ""));
  {
    Metric m = outcome_metric(tag + "N = 4.5 classified collapse", fl.run, CutOutcome::collapse);
    // A run that the growth guard stops before the crest has moved 0.05 H is not classified: the
    // instability at the slide's front (below) is the miss, and it is reported there too.
    if (!m.pass() && !fl.run.error.empty()) {
      m.known_deviation = fmt::format(
          "open: not classified, the run goes unstable at t = {:.2f} s (u_c = {:.2f} m) at the slide's front, before "
          "the crest has moved 0.05 H; whether the front survives is sensitive to the step (docs/VALIDATION.md Case 10)",
          fl.run.t.empty() ? 0.0 : fl.run.t.back(), fl.run.uc.empty() ? 0.0 : fl.run.uc.back());
    }
    rep.metrics.push_back(m);
  }
  rep.metrics.push_back(metric(tag + "N = 4.5: main scarp behind the original crest at the end, >= 0.7 H",
                               fl.scarp_end, ">=", 0.7 * kH, "m"));
  rep.metrics.push_back(metric(tag + "N = 4.5: main scarp behind the original crest at the end, <= 1.15 H",
                               fl.scarp_end, "<=", 1.15 * kH, "m"));
  rep.metrics.push_back(
      metric(tag + "N = 4.5: scarp behind the crest when u_c first exceeds 0.05 H", fl.scarp_onset, "", 0.0, "m"));
  rep.metrics.push_back(metric(tag + "N = 4.5: distance of the band (eps_vp_eq >= 50 % of max, reference positions) "
                                     "from the toe",
                               fl.toe_distance, "<=", 3.0 * dx, "m"));
  rep.metrics.push_back(metric(tag + "N = 4.5: crest displacement u_c at the end", fl.run.uc.back(), "", 0.0, "m"));
  for (const auto& [label, res] : {std::pair<std::string, const Result&>{"N = 3.4", st}, {"N = 4.5", fl}}) {
    const CutRun& run = res.run;
    // Why a criterion is not met (docs/VALIDATION.md Case 10): the runs' diagnosis.
    const std::string unstable = fmt::format(
        "open: the run goes unstable at t = {:.2f} s: nodes of the slide reaching the rough base in front of the toe "
        "stick beside nodes already there and cluster, and the corrected operators over the cluster blow up (V2 has "
        "no particle regularisation or contact repulsion, issue 12 item 5)",
        run.t.empty() ? 0.0 : run.t.back());
    {
      Metric m = metric(tag + label + ": run reached 20 s without the solver stopping", run.error.empty() ? 1.0 : 0.0,
                        ">=", 1.0, "");
      if (!m.pass()) m.known_deviation = unstable;
      rep.metrics.push_back(m);
    }
    {
      Metric m = metric(tag + label + ": time the kinetic energy first falls to 1e-4 of its peak (<= 20 s)",
                        std::isfinite(res.t_settled) ? res.t_settled : 1e9, "<=", 20.0 + 1e-6, "s");
      if (!m.pass()) {
        const std::size_t n = run.uc.size();
        std::size_t from = n;  // the first record of the last second
        while (from > 0 && !run.t.empty() && run.t[from - 1] >= run.t.back() - 1.0) --from;
        const double creep = n > 0 && from < n ? run.uc.back() - run.uc[from] : 0.0;
        if (!run.error.empty()) {
          m.known_deviation = unstable;
        } else if (label == "N = 3.4") {
          m.known_deviation = fmt::format(
              "open: the cut stands, but after the damping stops (t = 5 s) it keeps an elastic vibration of {:.2g} of "
              "the peak kinetic energy at 20 s (nodes at the toe's corner swing at a few cm/s): below yield nothing "
              "dissipates it but the hourglass control's mean-stress diffusion, about 2 % of a bending mode's energy a "
              "period (method-notes §2.6; the simple scheme it replaced damped more and smeared more); reaching 1e-4 "
              "needs the damping on beyond the ramp, which docs/cases.md Case 5 does not allow",
              res.ke_end_ratio);
        } else {
          m.known_deviation = fmt::format(
              "open: the slide has not come to rest by 20 s: {:.2g} of the peak kinetic energy, u_c still moving "
              "{:.2g} m in the last second, the deposit in front of the toe creeping over the rough base "
              "(docs/VALIDATION.md Case 10)",
              res.ke_end_ratio, creep);
        }
      }
      rep.metrics.push_back(m);
    }
    rep.metrics.push_back(metric(tag + label + ": kinetic energy / peak at the end", res.ke_end_ratio, "", 0.0, ""));
    rep.metrics.push_back(metric(tag + label +
                                     fmt::format(": flagged nodes off the alpha-shape boundary (r = {} dx), worst of "
                                                 "the records every {} s",
                                                 kAlpha, kTrackEvery),
                                 static_cast<double>(res.track.interior_flagged_max), "<=", 0.0, ""));
    if (!rep.metrics.back().pass()) {
      rep.metrics.back().known_deviation = fmt::format(
          "open: {} nodes flagged inside the cloud at t = {:.2f} s: gaps opening in the disordered toe region of the "
          "slide, where nodes cluster and separate (numerical fracture; no particle regularisation in V2)",
          res.track.interior_flagged_max, res.track.interior_flagged_t);
    }
    rep.metrics.push_back(metric(tag + label + ": mass change (nodes and stress points)", res.track.mass_change, "<=",
                                 1e-12, ""));
    rep.notes.push_back(run_note(label, res.run));
    rep.notes.push_back(fmt::format("{}: at the end {} nodes flagged, {} on the alpha-shape boundary, {} flagged off it; "
                                    "worst record {} at t = {:.2f} s",
                                    label, res.track.flagged_end, res.track.boundary_end, res.track.interior_flagged_end,
                                    res.track.interior_flagged_max, res.track.interior_flagged_t));
  }
  if (!opt.full) rep.notes.push_back("quick mode: dx = 0.5 m; --full runs docs/cases.md's 0.25 m");
  if (opt.plots) {
    std::string note;
    if (run_plot_script("plot_case10.py", dir, note)) {
      for (const char* p : {"case10/histories.png", "case10/eps_maps.png", "case10/geometry.png"}) rep.plots.push_back(p);
    } else {
      rep.notes.push_back(note);
    }
  }
  return rep;
}

}  // namespace rktsph::validation
