#include "validation/cut_common.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

const char* outcome_name(CutOutcome o) {
  switch (o) {
    case CutOutcome::stable:
      return "stable";
    case CutOutcome::collapse:
      return "collapse";
    default:
      return "undecided";
  }
}

namespace {
// Linear interpolation of a sampled history at time tq (clamped).
double sample_at(const std::vector<double>& t, const std::vector<double>& f, double tq) {
  if (tq <= t.front()) return f.front();
  if (tq >= t.back()) return f.back();
  const auto it = std::upper_bound(t.begin(), t.end(), tq);
  const auto k = static_cast<std::size_t>(it - t.begin());
  const double w = (tq - t[k - 1]) / (t[k] - t[k - 1]);
  return (1.0 - w) * f[k - 1] + w * f[k];
}
}  // namespace

Classification classify_cut(const std::vector<double>& t, const std::vector<double>& uc, const std::vector<double>& ke,
                            double H, double window) {
  Classification c;
  if (t.empty()) return c;
  const double t_end = t.back();
  c.uc_end = uc.back();
  double peak = 0.0, ke_window = 0.0;
  double umin = std::numeric_limits<double>::infinity(), umax = -umin;
  for (std::size_t k = 0; k < t.size(); ++k) {
    peak = std::max(peak, ke[k]);
    if (t[k] >= t_end - window - 1e-12) {
      ke_window = std::max(ke_window, ke[k]);
      umin = std::min(umin, uc[k]);
      umax = std::max(umax, uc[k]);
    }
  }
  c.uc_change = umax - umin;
  c.ke_ratio = peak > 0.0 ? ke_window / peak : 0.0;
  const double d_last = uc.back() - sample_at(t, uc, t_end - 0.5 * window);
  const double d_prev = sample_at(t, uc, t_end - 0.5 * window) - sample_at(t, uc, t_end - window);
  c.accelerating = d_last > 1e-3 * H && d_last > 1.1 * d_prev;
  if (c.uc_end > 0.05 * H || c.accelerating) {
    c.outcome = CutOutcome::collapse;
  } else if (c.uc_change < 1e-3 * H && c.ke_ratio <= 1e-2) {
    c.outcome = CutOutcome::stable;
  }
  return c;
}

CutSnapshot snapshot(const Simulation<2>& solver, double time) {
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  const bool has_eps = solver.history_layout().find("eps_vp_eq") >= 0;
  const auto v = solver.node_velocity();
  const auto u = solver.node_displacement();
  const auto sig = solver.node_stress();
  CutSnapshot s;
  s.time = time;
  // In the order the case made the nodes (V2 sorts them as they move): snapshots compare node
  // by node.
  const std::vector<Index> node_at = solver.nodes_by_id();
  for (std::size_t k = 0; k < nn; ++k) {
    const Index i = node_at[k];
    const auto iu = static_cast<std::size_t>(i);
    s.x.push_back(nodes.position[iu][0]);
    s.y.push_back(nodes.position[iu][1]);
    s.ux.push_back(u(i, 0));
    s.uy.push_back(u(i, 1));
    s.vx.push_back(v(i, 0));
    s.vy.push_back(v(i, 1));
    s.sxx.push_back(sig(i, StressComponent::xx));
    s.syy.push_back(sig(i, StressComponent::yy));
    s.sxy.push_back(sig(i, StressComponent::xy));
    s.eps.push_back(has_eps ? solver.node_history("eps_vp_eq")(i) : 0.0);
  }
  return s;
}

CutRun run_cut(const std::string& file, const std::vector<std::string>& overrides, double record_dt, double onset_uc,
               const StepHook& hook) {
  static std::map<std::string, CutRun> cache;
  std::string key = file + fmt::format("|{}|{}", record_dt, onset_uc);
  for (const auto& o : overrides) key += "|" + o;
  if (!hook) {
    const auto hit = cache.find(key);
    if (hit != cache.end()) return hit->second;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const CaseDocument doc = load_case_document(file, overrides);
  CaseSetup<2> setup = read_case<2>(doc);
  Simulation<2> solver(setup);
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  CutRun r;
  r.dx = setup.dx;
  r.dt = solver.dt();
  std::size_t crest = 0;
  for (std::size_t i = 0; i < nn; ++i) {
    r.width = std::max(r.width, nodes.position[i][0]);
    r.height = std::max(r.height, nodes.position[i][1]);
  }
  for (std::size_t i = 0; i < nn; ++i) {
    const auto& p = nodes.position[i];
    if (std::abs(p[0] - r.width) < 1e-9 && std::abs(p[1] - r.height) < 1e-9) crest = i;
  }
  // The crest node by global id: V2 sorts its nodes as they move.
  const std::int64_t crest_id = nodes.global_id[crest];
  long crest_sorted = solver.reorders();
  auto follow_crest = [&] {
    if (crest_sorted == solver.reorders()) return;
    crest = static_cast<std::size_t>(solver.node_with_id(crest_id));
    crest_sorted = solver.reorders();
  };
  auto record = [&]() {
    double ke = 0.0;
    for (std::size_t i = 0; i < nn; ++i) {
      const double vx = solver.node_velocity()(i, 0), vy = solver.node_velocity()(i, 1);
      ke += 0.5 * nodes.mass(static_cast<Index>(i)) * (vx * vx + vy * vy);
    }
    r.t.push_back(solver.time());
    r.uc.push_back(solver.node_displacement()(crest, 0));
    r.uyc.push_back(solver.node_displacement()(crest, 1));
    r.ke.push_back(ke);
  };
  const long steps = static_cast<long>(std::ceil(setup.end_time / solver.dt() - 1e-9));
  const long every = std::max(1L, static_cast<long>(std::lround(record_dt / solver.dt())));
  record();
  try {
    for (long n = 1; n <= steps; ++n) {
      solver.step();
      if (hook) hook(solver);
      follow_crest();
      const double uc = solver.node_displacement()(crest, 0);
      if (onset_uc > 0.0 && !r.has_onset && uc > onset_uc) {
        r.onset = snapshot(solver, solver.time());
        r.has_onset = true;
      }
      if (!r.has_collapse_state && uc > 0.05 * r.height) {
        r.at_collapse = snapshot(solver, solver.time());
        r.has_collapse_state = true;
      }
      if (n % every == 0 || n == steps) record();
    }
  } catch (const SolverError& e) {
    r.error = e.what();
  }
  r.final_state = snapshot(solver, solver.time());
  {
    // Traction residuals from the stress points next to the face and the top.
    const auto& el = solver.stress_points();
    const auto ne = static_cast<std::size_t>(el.size());
    std::map<long, std::pair<double, double>> face1, face2, top1, top2;  // row -> (s_n, s_t)
    double xmax = 0.0, ymax = 0.0;
    for (std::size_t e = 0; e < ne; ++e) {
      xmax = std::max(xmax, el.position[e][0]);
      ymax = std::max(ymax, el.position[e][1]);
    }
    for (std::size_t e = 0; e < ne; ++e) {
      const auto sig = solver.stress_point_stress();
      const double sxx = sig(e, StressComponent::xx), syy = sig(e, StressComponent::yy);
      const double sxy = sig(e, StressComponent::xy);
      const auto& p = el.position[e];
      const long row = std::lround(p[1] / r.dx * 2.0), col = std::lround(p[0] / r.dx * 2.0);
      if (std::abs(p[0] - xmax) < 1e-6 * r.dx) face1[row] = {sxx, sxy};
      if (std::abs(p[0] - (xmax - r.dx)) < 1e-6 * r.dx) face2[row] = {sxx, sxy};
      if (std::abs(p[1] - ymax) < 1e-6 * r.dx) top1[col] = {syy, sxy};
      if (std::abs(p[1] - (ymax - r.dx)) < 1e-6 * r.dx) top2[col] = {syy, sxy};
    }
    // Extrapolation to the boundary at distance (boundary - outer column) = W - xmax.
    const double fx = (r.width - xmax) / r.dx, fy = (r.height - ymax) / r.dx;
    double sum2 = 0.0;
    for (const auto& [row, a] : face1) {  // std::map: rows in increasing y
      const auto b = face2.find(row);
      if (b == face2.end()) continue;
      const double sn = a.first + fx * (a.first - b->second.first), st = a.second + fx * (a.second - b->second.second);
      const double res = std::max(std::abs(sn), std::abs(st));
      const double y = 0.5 * static_cast<double>(row) * r.dx;
      r.face_residual = std::max(r.face_residual, res);
      if (y >= 0.1 * r.height) r.face_residual_above_toe = std::max(r.face_residual_above_toe, res);
      if (y >= 2.0 * r.dx - 1e-9 * r.dx) r.face_residual_beyond_2dx = std::max(r.face_residual_beyond_2dx, res);
      r.face_rows.push_back({y, sn, st});
      sum2 += sn * sn + st * st;
    }
    if (!r.face_rows.empty()) r.face_residual_rms = std::sqrt(sum2 / static_cast<double>(r.face_rows.size()));
    for (const auto& [col, a] : top1) {
      const auto b = top2.find(col);
      if (b == top2.end()) continue;
      r.top_residual = std::max({r.top_residual, std::abs(a.first + fy * (a.first - b->second.first)),
                                 std::abs(a.second + fy * (a.second - b->second.second))});
    }
  }
  r.damping_off_time = solver.clock().damping_off_time();
  r.peak_ke = *std::max_element(r.ke.begin(), r.ke.end());
  r.steps = solver.step_count();
  r.max_substeps = solver.max_source_substeps();
  r.classification = classify_cut(r.t, r.uc, r.ke, r.height);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!hook) cache[key] = r;
  return r;
}

double at_node(const CutSnapshot& s, const std::vector<double>& field, double x, double y) {
  std::size_t best = 0;
  double d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double d = (s.x[i] - x) * (s.x[i] - x) + (s.y[i] - y) * (s.y[i] - y);
    if (d < d2) {
      d2 = d;
      best = i;
    }
  }
  return field[best];
}

double bilinear(const CutSnapshot& s, const std::vector<double>& field, double dx, double x, double y) {
  const double i0 = std::floor(x / dx + 1e-9), j0 = std::floor(y / dx + 1e-9);
  const double fx = x / dx - i0, fy = y / dx - j0;
  double acc = 0.0, wsum = 0.0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const double w = (a ? fx : 1.0 - fx) * (b ? fy : 1.0 - fy);
      if (w < 1e-12) continue;
      const double xn = (i0 + a) * dx, yn = (j0 + b) * dx;
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (std::abs(s.x[i] - xn) < 1e-6 * dx && std::abs(s.y[i] - yn) < 1e-6 * dx) {
          acc += w * field[i];
          wsum += w;
          break;
        }
      }
    }
  }
  return wsum > 0.0 ? acc / wsum : NAN;
}

void row_profile(const CutSnapshot& s, const std::vector<double>& field, double y0, double dx, std::vector<double>& xs,
                 std::vector<double>& fs) {
  std::vector<std::pair<double, double>> row;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (std::abs(s.y[i] - y0) < 1e-6 * dx) row.emplace_back(s.x[i], field[i]);
  }
  std::sort(row.begin(), row.end());
  xs.clear();
  fs.clear();
  for (const auto& [x, f] : row) {
    xs.push_back(x);
    fs.push_back(f);
  }
}

double fwhm(const std::vector<double>& x, const std::vector<double>& f, double xlo, double xhi, double& peak_x) {
  std::size_t k = x.size();
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i] < xlo || x[i] > xhi) continue;
    if (k == x.size() || f[i] > f[k]) k = i;
  }
  peak_x = NAN;
  if (k == x.size() || f[k] <= 0.0) return NAN;
  peak_x = x[k];
  const double half = 0.5 * f[k];
  double left = NAN, right = NAN;
  for (std::size_t i = k; i > 0; --i) {
    if (f[i - 1] < half) {
      left = x[i - 1] + (half - f[i - 1]) / (f[i] - f[i - 1]) * (x[i] - x[i - 1]);
      break;
    }
  }
  for (std::size_t i = k; i + 1 < x.size(); ++i) {
    if (f[i + 1] < half) {
      right = x[i] + (f[i] - half) / (f[i] - f[i + 1]) * (x[i + 1] - x[i]);
      break;
    }
  }
  return right - left;
}

double band_distance_to(const CutSnapshot& s, double px, double py, double ymin) {
  double emax = 0.0;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.y[i] >= ymin) emax = std::max(emax, s.eps[i]);
  }
  if (emax <= 0.0) return NAN;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.y[i] >= ymin && s.eps[i] >= 0.5 * emax) d = std::min(d, std::hypot(s.x[i] - px, s.y[i] - py));
  }
  return d;
}

void write_history_csv(const std::string& file, const CutRun& r) {
  std::ofstream f(file);
  f << "t,uc,uy_crest,kinetic\n";
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    f << fmt::format("{:.6g},{:.8g},{:.8g},{:.8g}\n", r.t[k], r.uc[k], r.uyc[k], r.ke[k]);
  }
}

void write_snapshot_csv(const std::string& file, const CutSnapshot& s) {
  std::ofstream f(file);
  f << "x,y,ux,uy,vx,vy,sxx,syy,sxy,eps_vp_eq\n";
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    f << fmt::format("{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", s.x[i], s.y[i], s.ux[i],
                     s.uy[i], s.vx[i], s.vy[i], s.sxx[i], s.syy[i], s.sxy[i], s.eps[i]);
  }
}

ToeScaling toe_scaling(const std::vector<double>& dx, const std::vector<double>& toe_residual, double lambda) {
  ToeScaling t;
  const std::size_t n = std::min(dx.size(), toe_residual.size());
  bool finite = n >= 2;
  for (std::size_t k = 0; k < n; ++k) {
    t.scaled.push_back(toe_residual[k] * std::pow(dx[k], 1.0 - lambda));
    finite = finite && std::isfinite(t.scaled.back());
  }
  if (!finite) {
    t.mean = t.max_deviation = NAN;
    return t;
  }
  for (double v : t.scaled) t.mean += v / static_cast<double>(n);
  for (double v : t.scaled) t.max_deviation = std::max(t.max_deviation, std::abs(v / t.mean - 1.0));
  return t;
}

double outcome_value(CutOutcome o) { return o == CutOutcome::stable ? 0.0 : (o == CutOutcome::collapse ? 1.0 : 2.0); }

Metric outcome_metric(const std::string& name, const CutRun& r, CutOutcome expected) {
  Metric m = metric(name + fmt::format(" (1 = yes; got {}: u_c = {:.3g} m, last-second change {:.2g} m, "
                                       "kinetic ratio {:.2g})",
                                       outcome_name(r.classification.outcome), r.classification.uc_end,
                                       r.classification.uc_change, r.classification.ke_ratio),
                    r.classification.outcome == expected ? 1.0 : 0.0, ">=", 1.0, "");
  return m;
}

std::string run_note(const std::string& label, const CutRun& r) {
  return fmt::format(
      "{}: dx = {} m, {} steps (dt = {:.3g} s), {:.1f} s wall, outcome {}, u_c(end) = {:.4g} m, "
      "u_c change over the last second {:.3g} m (stable below {:.3g}), kinetic energy in the last "
      "second / peak = {:.3g} (stable below 0.01), damping off at {}{}",
      label, r.dx, r.steps, r.dt, r.seconds, outcome_name(r.classification.outcome), r.classification.uc_end,
      r.classification.uc_change, 1e-3 * r.height, r.classification.ke_ratio,
      std::isfinite(r.damping_off_time) ? fmt::format("t = {:.2f} s", r.damping_off_time)
                                        : std::string("damping.until (the kinetic-energy switch did not fire)"),
      r.error.empty() ? "" : "; stopped: " + r.error);
}

}  // namespace rktsph::validation
