// `rktsph fos CASE`: trials of the case at reduced strength (or at a multiplied load), run in
// process (app/fos_trial.hpp) and side by side when threads allow, classified by the hold rule
// (app/fos_criterion.hpp; the load factor by docs/cases.md §1.3), searched by
// app/fos_search.cpp.
#include "app/fos.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "app/fos_search.hpp"
#include "app/fos_setup.hpp"
#include "app/fos_trial.hpp"
#include "app/signals.hpp"
#include "core/error.hpp"
#include "io/output_files.hpp"
#include "validation/cut_common.hpp"
#include "validation/validation.hpp"

namespace rktsph {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Trial {
  int index = 0;  // 1-based, in the order the trials were started
  double factor = 0.0;
  fs::path history_file;  // trial_NN.csv
  fs::path frame_file;    // trial_NN.vtu
  fos::TrialResult result;
  std::string error;  // the trial could not run at all (its input refused)
  int exit_code = -1;
  // The load factor's classification (CASES.md §1.3) on the histories.
  std::vector<double> ke_at_t;  // the kinetic energy at the monitor's sample times
  validation::Classification classification;
  std::string outcome;  // stable, collapse, undecided (load factor), or unstable (the solver stopped)
  bool stable = false;
  bool used = false;  // on the sequential search's path (else speculative)
};

// Linear interpolation of f(t) at tq (clamped); t increasing.
double interpolate(const std::vector<double>& t, const std::vector<double>& f, double tq) {
  if (t.empty()) return 0.0;
  if (tq <= t.front()) return f.front();
  if (tq >= t.back()) return f.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), tq) - t.begin());
  const double w = (tq - t[k - 1]) / (t[k] - t[k - 1]);
  return (1.0 - w) * f[k - 1] + w * f[k];
}

// The trial's outcome: by the hold rule (strength reduction, decided while it ran), or by the
// window rule of CASES.md §1.3 on its histories (the load factor).
void classify(Trial& tr, const fos::Monitor& m, bool by_hold) {
  const fos::TrialHistory& h = tr.result.history;
  tr.ke_at_t.clear();
  const std::vector<double>& kinetic =
      m.kinetic_column == "kinetic_stress_points" ? h.kinetic_stress_points : h.kinetic;
  for (double t : h.t) tr.ke_at_t.push_back(interpolate(h.energy_t, kinetic, t));
  if (!by_hold && !h.t.empty()) tr.classification = validation::classify_cut(h.t, h.uc, tr.ke_at_t, m.length, m.window);
  if (tr.exit_code == kExitUnstable) {
    tr.outcome = "unstable";
    tr.stable = false;
  } else if (by_hold) {
    tr.outcome = fos::hold_outcome_name(tr.result.hold_outcome);
    tr.stable = tr.result.hold_outcome == fos::HoldOutcome::stable;
  } else {
    tr.outcome = validation::outcome_name(tr.classification.outcome);
    tr.stable = tr.classification.outcome == validation::CutOutcome::stable;
  }
}

void write_history(const Trial& tr) {
  const fos::TrialHistory& h = tr.result.history;
  // The monitor's samples, the energies interpolated to their times: the kinetic energy the
  // classification reads, both sets' own, the plastic dissipation.
  std::string text = "t,u_c,kinetic,kinetic_nodes,kinetic_stress_points,plastic_dissipation\n";
  for (std::size_t k = 0; k < h.t.size(); ++k) {
    text += fmt::format("{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}\n", h.t[k], h.uc[k], tr.ke_at_t[k],
                        interpolate(h.energy_t, h.kinetic, h.t[k]),
                        interpolate(h.energy_t, h.kinetic_stress_points, h.t[k]),
                        interpolate(h.energy_t, h.plastic, h.t[k]));
  }
  io::write_file_atomically(tr.history_file.string(), text, false);
}

// Make the search's folder: new, empty, or the folder of an earlier search (whose trials go).
void prepare_folder(const fs::path& out) {
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    throw InputError(fmt::format("--out '{}': exists and is not a folder", out.string()));
  }
  if (fs::is_directory(out, ec) && !fs::is_empty(out, ec)) {
    if (!fs::exists(out / "fos.json")) {
      throw InputError(fmt::format("--out '{}': the folder holds files that are not the output of rktsph fos; "
                                   "choose an empty or new folder",
                                   out.string()));
    }
    for (const auto& e : fs::directory_iterator(out)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("trial_", 0) == 0 || name == "fos.json" || name == "fos_uc.png") fs::remove_all(e.path());
    }
  }
  fs::create_directories(out, ec);
  if (ec) throw InputError(io::system_error_text("create the output folder", out.string(), ec.value()));
}

// What a factor F changes in a trial: the strengths (divided by F) or the loads (times F).
struct Scaling {
  fos::FactorMode mode = fos::FactorMode::strength;
  fos::StrengthReduction strength;
  fos::LoadScaling load;
  bool by_load() const { return mode == fos::FactorMode::load; }
  void apply(toml::table& root, double f) const { by_load() ? load.apply(root, f) : strength.apply(root, f); }
  std::vector<std::pair<std::string, double>> values(double f) const {
    return by_load() ? load.values(f) : strength.values(f);
  }
  // The factor's name in messages and in fos.json.
  const char* name() const { return by_load() ? "load factor" : "factor of safety"; }
  const char* key() const { return by_load() ? "load_factor" : "factor_of_safety"; }
};

// The plastic work done over [a, b] (J), from the energy history.
double plastic_work(const fos::TrialHistory& h, double a, double b) {
  return interpolate(h.energy_t, h.plastic, b) - interpolate(h.energy_t, h.plastic, a);
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json trial_json(const Trial& tr, const fs::path& out, const Scaling& scaling, const fos::Monitor& m) {
  const fos::TrialResult& r = tr.result;
  const fos::TrialHistory& h = r.history;
  double u_max = h.uc.empty() ? 0.0 : h.uc.front();
  for (double u : h.uc) u_max = std::max(u_max, u);
  nlohmann::json changed = nlohmann::json::object();
  for (const auto& [key, value] : scaling.values(tr.factor)) changed[key] = value;
  nlohmann::json j = {
      {"index", tr.index},
      {"factor", tr.factor},
      {"outcome", tr.outcome},
      {"stable", tr.stable},
      {"used", tr.used},
      {"history", fs::relative(tr.history_file, out).string()},
      {"exit_code", tr.exit_code},
      {"seconds", r.seconds},
      {"steps", r.steps},
      {"t_end", r.end_time},
      {scaling.by_load() ? "scaled" : "reduced", changed},
  };
  if (fs::exists(tr.frame_file)) j["frame"] = fs::relative(tr.frame_file, out).string();
  if (scaling.by_load()) {
    const auto& c = tr.classification;
    j["u_c"] = {{"end", c.uc_end},
                {"max", u_max},
                {"change_last_window", c.uc_change},
                {"accelerating", c.accelerating},
                {"samples", h.t.size()}};
    j["kinetic_ratio_last_window"] = c.ke_ratio;
  } else {
    const fos::HoldMeasures& hm = r.hold;
    const double mid = m.hold_start + 0.5 * m.hold;
    const double w1 = plastic_work(h, m.hold_start, std::min(mid, r.end_time));
    const double w2 = r.end_time > mid ? plastic_work(h, mid, r.end_time) : 0.0;
    j["hold"] = {{"drift_first_half", hm.first_half},
                 {"drift_second_half", hm.second_half},
                 {"ratio", finite_or_null(hm.ratio)},
                 {"large_displacement", hm.large_displacement},
                 {"decided_at", finite_or_null(hm.decided_at)},
                 {"plastic_work_first_half", w1},
                 {"plastic_work_second_half", w2}};
    j["u_c"] = {{"end", hm.uc}, {"max", hm.uc_max}, {"samples", h.t.size()}};
  }
  if (!tr.error.empty()) {
    j["message"] = tr.error;
  } else if (!r.message.empty()) {
    j["message"] = r.message;
  }
  return j;
}

std::string bracket_text(const fos::SearchStatus& s) {
  if (!std::isfinite(s.hi)) return s.lo > 0.0 ? fmt::format("[{:.4f}, -)", s.lo) : std::string("[-, -)");
  if (s.lo <= 0.0) return fmt::format("[-, {:.4f}]", s.hi);
  return fmt::format("[{:.4f}, {:.4f}] ({:.2f} % wide)", s.lo, s.hi, 100.0 * (s.hi - s.lo) / s.lo);
}

}  // namespace

int run_fos(const FosOptions& opt) {
  const auto t_start = Clock::now();
  std::vector<std::string> case_overrides = opt.overrides;
  if (!opt.solver.empty()) case_overrides.push_back("solver.version=" + nlohmann::json(opt.solver).dump());
  // Everything is checked before a folder is touched: the case, its strengths, the [fos] table
  // and the monitored node.
  const CaseDocument doc = load_case_document(opt.case_file, case_overrides);
  fos::FosTable table = fos::read_fos_table(doc);
  Scaling scaling;
  scaling.mode = table.mode;
  if (scaling.by_load()) {
    scaling.load = fos::read_load_scaling(doc, table);
  } else {
    scaling.strength = fos::read_strength(doc);
    scaling.strength.rate_independent = table.rate_independent;
  }
  if (opt.tolerance > 0.0) table.search.tolerance = opt.tolerance;
  if (opt.max_trials > 0) table.search.max_trials = opt.max_trials;
  const fos::SearchSettings& settings = table.search;
  const fos::Monitor monitor = fos::resolve_monitor(doc, table);
  const bool by_hold = !scaling.by_load();
  const std::string solver_version = [&] {
    const auto v = doc.table["solver"]["version"].value<std::string>();
    return v ? *v : std::string("v1");
  }();
  // A trial's rule: strength reduction by the hold after time.end (app/fos_criterion.hpp), the
  // load factor by the last window of the case's run (CASES.md §1.3).
  fos::HoldRule hold_rule;
  hold_rule.hold_start = monitor.hold_start;
  hold_rule.hold = monitor.hold;
  hold_rule.length = monitor.length;

  const fs::path out = opt.out_dir.empty() ? fs::path("out") / (fs::path(opt.case_file).stem().string() + "_fos")
                                           : fs::path(opt.out_dir);
  prepare_folder(out);

  const int threads = std::max(1, opt.threads);
  const int jobs = std::clamp(opt.jobs > 0 ? opt.jobs : threads, 1, 64);
  const int threads_per_trial = std::max(1, threads / jobs);
  const std::string rule_text =
      by_hold ? fmt::format("hold {:.4g} s after time.end = {:.4g} s ({}{})", monitor.hold, monitor.hold_start,
                            monitor.time_scale > 0.0
                                ? fmt::format("{:.3g} time scales sqrt(L/g) = {:.3g} s", monitor.hold / monitor.time_scale,
                                              monitor.time_scale)
                                : std::string("no gravity: the case's time.end"),
                            scaling.strength.rate_independent ? "; materials rate-independent" : "; the case's fluidity")
              : fmt::format("window {} s", monitor.window);
  if (!opt.quiet) {
    std::cerr << fmt::format(
        "rktsph fos: {} ({}, dx = {:.4g} m, h = {:.4g} m), {}, monitor at [{}] along [{}] ({}), length {} m, {}; "
        "tolerance {} on F, at most {} trials, {} at once ({} thread{} each)\n",
        opt.case_file, solver_version, monitor.spacing, monitor.smoothing_length,
        scaling.by_load() ? fmt::format("load factor on {}", fmt::join(table.load_functions, ", "))
                          : std::string("strength reduction"),
        fmt::join(monitor.position, ", "), fmt::join(monitor.direction, ", "), monitor.source, monitor.length,
        rule_text, settings.tolerance, settings.max_trials, jobs, threads_per_trial, threads_per_trial > 1 ? "s" : "");
  }

  std::vector<Trial> trials;
  std::map<double, bool> known;
  std::vector<fos::Step> path;
  fos::SearchStatus status;
  std::string failure;  // a trial that could not be run at all
  int failure_code = 0;
  bool non_monotone = false;

  auto write_json = [&](const std::string& state, const std::string& message) {
    nlohmann::json j;
    j["case"] = opt.case_file;
    j["overrides"] = opt.overrides;
    j["solver"] = solver_version;
    j["status"] = state;
    j["message"] = message;
    j["mode"] = scaling.by_load() ? "load" : "strength";
    const double f = status.factor();
    j["factor"] = std::isfinite(f) ? nlohmann::json(f) : nlohmann::json(nullptr);
    j[scaling.key()] = j["factor"];
    j["bracket"] = {status.lo > 0.0 ? nlohmann::json(status.lo) : nlohmann::json(nullptr),
                    std::isfinite(status.hi) ? nlohmann::json(status.hi) : nlohmann::json(nullptr)};
    j["tolerance"] = settings.tolerance;
    j["max_trials"] = settings.max_trials;
    j["growth"] = settings.growth;
    j["trials_used"] = path.size();
    j["trials_run"] = trials.size();
    j["jobs"] = jobs;
    j["threads_per_trial"] = threads_per_trial;
    j["non_monotone"] = non_monotone;
    j["spacing"] = monitor.spacing;
    j["smoothing_length"] = monitor.smoothing_length;
    j["monitor"] = {{"position", monitor.position}, {"direction", monitor.direction},    {"length", monitor.length},
                    {"kinetic", monitor.kinetic_column}, {"source", monitor.source}};
    if (by_hold) {
      j["monitor"]["hold_start"] = monitor.hold_start;
      j["monitor"]["hold"] = monitor.hold;
      j["monitor"]["time_scale"] = monitor.time_scale;
      j["rate_independent"] = scaling.strength.rate_independent;
      j["classification"] = fmt::format(
          "method-notes eq. (10.5): over the hold of {} s after time.end = {} s the monitored node drifts at v1 over "
          "the first half and v2 over the second (least-squares slopes of its displacement); collapse if u_c > {} L "
          "at any time, or if v2 h/2 > {} L and v2 >= {} v1 (the motion does not die out), otherwise stable. A trial "
          "the solver stops counts as not stable.",
          hold_rule.hold, hold_rule.hold_start, hold_rule.collapse, hold_rule.rest, hold_rule.decay);
    } else {
      j["monitor"]["window"] = monitor.window;
      j["classification"] =
          "docs/cases.md §1.3 on u_c = u . direction at the monitored node, with H = length: stable if over the last "
          "window u_c changes by less than 1e-3 H and the kinetic energy stays below 1e-2 of its peak; collapse if "
          "u_c > 0.05 H or u_c still accelerates; otherwise undecided. Undecided and unstable trials count as not "
          "stable.";
    }
    if (scaling.by_load()) {
      nlohmann::json loads = nlohmann::json::object();
      for (const auto& [table_name, scale] : scaling.load.functions) loads[table_name + ".scale"] = scale;
      j["load_functions"] = loads;  // the unscaled scales; a trial at F has F times each
    } else {
      nlohmann::json mats = nlohmann::json::array();
      for (const auto& m : scaling.strength.materials) {
        nlohmann::json e = {{"table", m.table}, {"model", m.model}};
        for (const auto& [key, value] : m.divided) e["divided_by_F"][key] = value;
        if (m.friction_angle) e["friction_angle"] = *m.friction_angle;
        if (m.dilatancy) e["dilatancy"] = *m.dilatancy;
        mats.push_back(e);
      }
      j["strength"] = mats;
      j["unreduced_materials"] = scaling.strength.unreduced;
    }
    j["trials"] = nlohmann::json::array();
    for (const Trial& tr : trials) j["trials"].push_back(trial_json(tr, out, scaling, monitor));
    j["wall_seconds"] = std::chrono::duration<double>(Clock::now() - t_start).count();
    io::write_file_atomically((out / "fos.json").string(), j.dump(2) + "\n");
  };

  // A trial that could not be run at all (bad reduced input, a write error, a signal) ends the search.
  struct TrialFailure {};
  auto mark_used = [&] {
    for (Trial& tr : trials) {
      tr.used = std::any_of(path.begin(), path.end(), [&](const fos::Step& s) { return s.factor == tr.factor; });
    }
  };
  install_stop_handlers();
  auto evaluate = [&](const std::vector<double>& batch) {
    mark_used();
    status = fos::status_after(settings, path);
    if (!trials.empty()) write_json("running", "");
    const std::size_t first = trials.size();
    for (double f : batch) {
      Trial tr;
      tr.index = static_cast<int>(trials.size()) + 1;
      tr.factor = f;
      tr.history_file = out / fmt::format("trial_{:02d}.csv", tr.index);
      tr.frame_file = out / fmt::format("trial_{:02d}.vtu", tr.index);
      trials.push_back(std::move(tr));
    }
    if (!opt.quiet) {
      std::vector<std::string> fs_text;
      for (double f : batch) fs_text.push_back(fmt::format("{:.4f}", f));
      std::cerr << fmt::format("fos: bracket {}, {} of {} trials used, {} run; running F = {}{}\n",
                               bracket_text(status), path.size(), settings.max_trials, first, fmt::join(fs_text, ", "),
                               batch.size() > 1 ? fmt::format(" ({} at once)", batch.size()) : std::string());
    }
    // Each trial in process: the case's document at its factor, a Simulation, an observer of
    // the monitored node (app/fos_trial.hpp).
    auto run_one = [&](Trial& tr) {
      try {
        CaseDocument trial_doc = doc;
        scaling.apply(trial_doc.table, tr.factor);
        fos::TrialSpec spec;
        spec.document = &trial_doc;
        spec.monitor = monitor;
        if (by_hold) {
          spec.hold = hold_rule;
          // The run continues past the case's time.end through the hold.
          trial_doc.table["time"].as_table()->insert_or_assign("end", hold_rule.end());
        }
        spec.threads = threads_per_trial;
        spec.frame = tr.frame_file;
        tr.result = fos::run_trial(spec);
        tr.exit_code = tr.result.exit_code;
      } catch (const InputError& e) {
        tr.exit_code = kExitInput;
        tr.error = e.what();
      } catch (const IoError& e) {
        tr.exit_code = kExitIo;
        tr.error = e.what();
      } catch (const std::exception& e) {
        tr.exit_code = 1;
        tr.error = e.what();
      }
    };
    if (batch.size() == 1) {
      run_one(trials[first]);
    } else {
      std::vector<std::thread> workers;
      for (std::size_t k = first; k < trials.size(); ++k) workers.emplace_back(run_one, std::ref(trials[k]));
      for (auto& w : workers) w.join();
    }
    std::vector<bool> stable;
    for (std::size_t k = first; k < trials.size(); ++k) {
      Trial& tr = trials[k];
      if (tr.exit_code != 0 && tr.exit_code != kExitUnstable) {
        if (failure.empty()) {
          failure_code = tr.exit_code;
          failure = tr.error.empty() ? fmt::format("trial {} (F = {:.4f}) stopped with exit status {}{}", tr.index,
                                                   tr.factor, tr.exit_code,
                                                   tr.exit_code > 128 ? fmt::format(" (signal {}: interrupted)",
                                                                                    tr.exit_code - 128)
                                                                      : std::string())
                                     : fmt::format("trial {} (F = {:.4f}): {}", tr.index, tr.factor, tr.error);
        }
        tr.outcome = "failed";
        continue;
      }
      classify(tr, monitor, by_hold);
      write_history(tr);
      stable.push_back(tr.stable);
      if (!opt.quiet) {
        const fos::TrialResult& r = tr.result;
        const std::string measures =
            by_hold ? fmt::format("v2/v1 = {:.3g} ({:.3g} / {:.3g} m/s), u_c = {:.4g} m = {:.3g} L{}", r.hold.ratio,
                                  r.hold.second_half, r.hold.first_half, r.hold.uc, r.hold.uc / monitor.length,
                                  std::isfinite(r.hold.decided_at) && r.hold.decided_at < hold_rule.end() - 1e-9
                                      ? fmt::format(", decided at t = {:.3g} s", r.hold.decided_at)
                                      : std::string())
                    : fmt::format("u_c = {:.4g} m = {:.3g} L", tr.classification.uc_end,
                                  tr.classification.uc_end / monitor.length);
        std::cerr << fmt::format("fos: trial {} F = {:.4f}: {} ({}; {:.1f} s)\n", tr.index, tr.factor, tr.outcome,
                                 measures, r.seconds);
      }
    }
    if (!failure.empty()) throw TrialFailure{};
    return stable;
  };
  try {
    status = fos::run_search(settings, jobs, evaluate, path, known);
  } catch (const TrialFailure&) {
    status = fos::status_after(settings, path);
  }
  mark_used();
  for (const auto& [fa, sa] : known) {
    for (const auto& [fb, sb] : known) non_monotone = non_monotone || (sa && !sb && fa > fb);
  }

  if (!failure.empty()) {
    const int code = failure_code == kExitInput || failure_code == kExitIo || failure_code > 128 ? failure_code : 1;
    const std::string message = fmt::format("rktsph fos: {}; the trials so far are kept in {}", failure, out.string());
    write_json("failed", message);
    std::cerr << "error: " << message << "\n";
    return code;
  }
  if (non_monotone) {
    std::cerr << "warning: rktsph fos: a trial stood at a larger F than one that did not (the classification is "
                 "not monotone in F; see fos.json)\n";
  }
  std::string message;
  int code = 0;
  const Trial* first_trial = trials.empty() ? nullptr : &trials.front();
  switch (status.state) {
    case fos::SearchState::converged:
      message = fmt::format("{} F = {:.4f}, bracket [{:.4f}, {:.4f}] (tolerance {} relative), {} trials used, {} run",
                            scaling.name(), status.factor(), status.lo, status.hi, settings.tolerance, path.size(),
                            trials.size());
      break;
    case fos::SearchState::unreduced_fails: {
      const double uc = by_hold ? first_trial->result.hold.uc : first_trial->classification.uc_end;
      message = fmt::format(
          "rktsph fos: the {} (F = {}) does not stand: trial 1 is {} (u_c = {:.4g} m = {:.3g} L at the end); {}; "
          "its history is kept in {}",
          scaling.by_load() ? "case at its nominal load" : "unreduced case", settings.start, first_trial->outcome, uc,
          uc / monitor.length,
          scaling.by_load() ? "the load factor is searched from F = 1 up: give a nominal load the body carries"
                            : "strength reduction looks for F >= 1 only",
          first_trial->history_file.string());
      code = kExitNoFactor;
      break;
    }
    default:
      message = fmt::format(
          "rktsph fos: the bracket {} did not close to the tolerance {} within {} trials{}; raise --max-trials{}; the "
          "trials are kept in {}",
          bracket_text(status), settings.tolerance, settings.max_trials,
          std::isfinite(status.hi) ? "" : " (every trial stood)",
          std::isfinite(status.hi) ? " or --tol" : " or fos.growth", out.string());
      code = kExitNoFactor;
      break;
  }
  write_json(fos::state_name(status.state), code == 0 ? "" : message);
  if (opt.plot) {
    std::string note;
    if (!validation::run_plot_script("plot_fos.py", out.string(), note)) std::cerr << "warning: " << note << "\n";
  }
  if (code == 0) {
    std::cerr << fmt::format("rktsph fos: {}; {:.1f} s; fos.json in {}\n", message,
                             std::chrono::duration<double>(Clock::now() - t_start).count(), out.string());
    std::cout << fmt::format("{:.6g}\n", status.factor());
  } else {
    std::cerr << "error: " << message << "\n";
  }
  return code;
}

}  // namespace rktsph
