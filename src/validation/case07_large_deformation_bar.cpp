// Thesis case 7: 1D elastic bar in large deformation, pushed and pulled (docs/cases.md Case 7):
// V2 against the exact shock and rarefaction-fan solutions of the Jaumann hypoelastic law
// (sigma = M ln lambda), and against V1's small-strain solution.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "validation/analytic.hpp"
#include "validation/validation.hpp"

namespace rktsph::validation {

namespace fs = std::filesystem;

namespace {

constexpr double kL = 10.0, kM = 1.0e7, kRho = 2000.0;
const double kC0 = std::sqrt(kM / kRho);
const double kV0 = 0.2 * kC0;  // 14.142 m/s
constexpr double kTimes[2] = {0.06, 0.12};

struct Profile {
  double t = 0.0;
  std::vector<double> X, x, lambda, sigma, v, rho, lambda_exact, sigma_exact, v_exact;
};

struct BarRun {
  std::vector<Profile> profiles;                  // at kTimes
  std::vector<double> track_t;                    // trajectories
  std::vector<std::vector<double>> track_x;       // [time][tracked particle]
  std::vector<double> track_X;
  double mass_change = 0.0;  // max |sum m - sum m0| / sum m0 over the run
  long steps = 0;
  double seconds = 0.0;
};

// Profiles in the reference coordinate X (the initial position), lambda = dx/dX by central
// differences of the current positions x = X + u (V1's particles stay at X: x = X + u too).
template <int Dim>
Profile profile(const Simulation<Dim>& s, const std::vector<double>& X0, const analytic::LargeStrainBar& exact) {
  Profile p;
  p.t = s.time();
  const auto& nodes = s.nodes();
  const auto n = static_cast<std::size_t>(nodes.size());
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return X0[a] < X0[b]; });
  for (std::size_t i : order) {
    p.x.push_back(X0[i] + s.node_displacement()(i, 0));
    p.X.push_back(X0[i]);
    p.sigma.push_back(s.node_stress()(i, StressComponent::xx));
    p.v.push_back(s.node_velocity()(i, 0));
    p.rho.push_back(nodes.density[i]);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? k : k + 1;
    p.lambda.push_back((p.x[b] - p.x[a]) / (p.X[b] - p.X[a]));
    p.lambda_exact.push_back(exact.lambda(p.X[k], p.t));
    p.sigma_exact.push_back(exact.stress(p.X[k], p.t));
    p.v_exact.push_back(exact.velocity(p.X[k], p.t));
  }
  return p;
}

// velocity_update empty: the case file's (its default, V2's).
BarRun run_bar(const std::string& case_file, double dx, double v0, const std::string& version,
               const std::string& velocity_update = "", const std::string& dt_rule = "fixed") {
  std::vector<std::string> overrides{fmt::format("geometry.spacing={}", dx),
                                     fmt::format("boundary.0.velocity.x={:.17g}", v0),
                                     fmt::format("solver.version=\"{}\"", version),
                                     fmt::format("time.dt_rule=\"{}\"", dt_rule), "output.times=[]"};
  if (!velocity_update.empty()) overrides.push_back(fmt::format("solver.velocity_update=\"{}\"", velocity_update));
  const CaseDocument doc = load_case_document(case_file, overrides);
  Simulation<1> solver(read_case<1>(doc));
  const analytic::LargeStrainBar exact{kM, kRho, v0};
  BarRun out;
  const auto t0 = std::chrono::steady_clock::now();
  auto total_mass = [&] {
    double m = 0.0;
    for (Index i = 0; i < solver.nodes().size(); ++i) m += solver.nodes().mass(i);
    return m;
  };
  const double m0 = total_mass();
  std::vector<double> X0;
  for (const auto& x : solver.nodes().position) X0.push_back(x[0]);
  for (std::size_t i = 0; i < static_cast<std::size_t>(solver.nodes().size()); i += 10) {
    out.track_X.push_back(solver.nodes().position[i][0]);
  }
  const long record_every = std::max(1L, std::lround(0.002 / solver.dt()));
  std::size_t next = 0;
  while (next < 2) {
    solver.step();
    if (solver.step_count() % record_every == 0) {
      out.track_t.push_back(solver.time());
      std::vector<double> xs;
      for (std::size_t i = 0; i < static_cast<std::size_t>(solver.nodes().size()); i += 10) {
        xs.push_back(X0[i] + solver.node_displacement()(i, 0));
      }
      out.track_x.push_back(std::move(xs));
      out.mass_change = std::max(out.mass_change, std::abs(total_mass() - m0) / m0);
    }
    if (solver.time() >= kTimes[next] - 1e-9) out.profiles.push_back(profile(solver, X0, exact)), ++next;
  }
  out.steps = solver.step_count();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

// X where sigma (from the driven end) first crosses half of `jump`.
double front_position(const Profile& p, double jump) {
  for (std::size_t k = 0; k + 1 < p.X.size(); ++k) {
    const double a = p.sigma[k] / jump, b = p.sigma[k + 1] / jump;
    if (a >= 0.5 && b < 0.5) return p.X[k] + (a - 0.5) / (a - b) * (p.X[k + 1] - p.X[k]);
  }
  return NAN;
}

void write_profiles(const std::string& file, const BarRun& r) {
  std::ofstream f(file);
  f << "t,X,x,lambda,lambda_exact,sigma,sigma_exact,v,v_exact,rho\n";
  for (const Profile& p : r.profiles) {
    for (std::size_t k = 0; k < p.X.size(); ++k) {
      f << fmt::format("{:.6g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}\n", p.t, p.X[k],
                       p.x[k], p.lambda[k], p.lambda_exact[k], p.sigma[k], p.sigma_exact[k], p.v[k], p.v_exact[k],
                       p.rho[k]);
    }
  }
}

void write_tracks(const std::string& file, const BarRun& r) {
  std::ofstream f(file);
  f << "t";
  for (double X : r.track_X) f << fmt::format(",X{:.4g}", X);
  f << "\n";
  for (std::size_t k = 0; k < r.track_t.size(); ++k) {
    f << fmt::format("{:.6g}", r.track_t[k]);
    for (double x : r.track_x[k]) f << fmt::format(",{:.10g}", x);
    f << "\n";
  }
}

}  // namespace

CaseReport validate_case07(const Options& opt, const std::string& dir) {
  CaseReport rep;
  rep.id = "07";
  rep.title = "1D elastic bar in large deformation, pushed and pulled (V2)";
  rep.reference = "exact shock and rarefaction-fan solutions of sigma = M ln(lambda) (docs/cases.md Case 7)";
  const std::string case_file = (fs::path(opt.cases_dir) / "07_large_deformation_bar_1d.toml").string();
  const analytic::LargeStrainBar push{kM, kRho, kV0}, pull{kM, kRho, -kV0};
  const double sigma_push = kM * std::log(push.lambda_behind()), sigma_pull = kM * std::log(pull.lambda_behind());
  rep.notes.push_back(fmt::format("exact: push lambda1 = {:.5f}, sigma1 = {:.5g} Pa, shock speed {:.5g} m/s = {:.4f} C0; "
                                  "pull lambda1 = {:.4f}, sigma1 = {:.5g} Pa, fan {:.5g} .. {:.5g} m/s",
                                  push.lambda_behind(), sigma_push, push.shock_speed(), push.shock_speed() / kC0,
                                  pull.lambda_behind(), sigma_pull, pull.fan_tail(), pull.fan_head()));
  double total_seconds = 0.0;
  // The thesis resolutions with the fixed step, and the coarse one again with the step from the
  // current state (time.dt_rule = "current", method-notes eq. (4.3.3)).
  const std::vector<std::pair<double, std::string>> runs = {{0.05, "fixed"}, {0.025, "fixed"}, {0.05, "current"}};
  for (const auto& [dx, rule] : runs) {
    const bool fixed = rule == "fixed";
    const std::string tag = fmt::format("dx{}{}", dx, fixed ? "" : "_current_dt");
    // A row's name: "push, dx = 0.05: what" (", dt_rule current" before the colon).
    auto row = [&, dx = dx](const char* load, const std::string& what) {
      return fmt::format("{}, dx = {}{}: {}", load, dx, fixed ? "" : ", dt_rule current", what);
    };
    // ---- push: one shock
    const BarRun p = run_bar(case_file, dx, kV0, "v2", "", rule);
    write_profiles(fmt::format("{}/push_{}.csv", dir, tag), p);
    write_tracks(fmt::format("{}/push_tracks_{}.csv", dir, tag), p);
    total_seconds += p.seconds;
    double worst_front = 0.0, worst_lambda = 0.0, worst_sigma = 0.0, worst_overshoot = 0.0, worst_rho = 0.0;
    for (const Profile& pr : p.profiles) {
      const double xs = push.shock_speed() * pr.t;
      worst_front = std::max(worst_front, std::abs(front_position(pr, sigma_push) - xs) / dx);
      double lam = 0.0, sig = 0.0;
      int count = 0;
      double smin = 0.0;
      for (std::size_t k = 0; k < pr.X.size(); ++k) {
        if (pr.X[k] > 0.2 * xs && pr.X[k] < 0.8 * xs) {
          lam += pr.lambda[k];
          sig += pr.sigma[k];
          ++count;
        }
        smin = std::min(smin, pr.sigma[k]);
        // lambda by central differences: every node but the two ends.
        if (k > 0 && k + 1 < pr.X.size()) worst_rho = std::max(worst_rho, std::abs(pr.rho[k] * pr.lambda[k] / kRho - 1.0));
      }
      worst_lambda = std::max(worst_lambda, std::abs(lam / count / push.lambda_behind() - 1.0));
      worst_sigma = std::max(worst_sigma, std::abs(sig / count / sigma_push - 1.0));
      worst_overshoot = std::max(worst_overshoot, smin / sigma_push - 1.0);
    }
    {
      Metric front = metric(row("push", "shock position error at 0.06 / 0.12 s (max)"), worst_front, "<=", 2.0, "dx");
      if (!front.pass()) {
        front.known_deviation =
            "the second-order step is dispersive: behind the front it leaves a trailing wave train (lambda down to "
            "0.787 against the plateau's 0.810 at dx = 0.05 m) that takes up part of the compression, so the "
            "mid-jump lags the exact shock by 0.14 m at dx = 0.05 m and 0.11 m at dx = 0.025 m (2.8 and 4.2 dx: it "
            "converges, slowly); the shock limiter (method-notes eq. (2.6.4)) blends the simple scheme in at the "
            "front only, where the compression Mach number is 0.2, not in the train behind it (Mach 0.004); the "
            "simple scheme alone is within 2 dx";
      }
      rep.metrics.push_back(front);
    }
    rep.metrics.push_back(
        metric(row("push", "plateau lambda error"), worst_lambda, "<=", 0.02, ""));
    rep.metrics.push_back(metric(row("push", "plateau sigma error"), worst_sigma, "<=", 0.02, ""));
    rep.metrics.push_back(metric(row("push", "overshoot at the shock / jump"), worst_overshoot,
                                 "<=", 0.20, ""));
    rep.metrics.push_back(metric(row("push", "max |rho lambda / rho0 - 1| (nodes but the ends)"),
                                 worst_rho, "<=", 0.01, ""));
    rep.metrics.push_back(
        metric(row("push", "mass change sum m / sum m0 - 1"), p.mass_change, "<=", 1e-12, ""));

    // ---- pull: a rarefaction fan
    const BarRun q = run_bar(case_file, dx, -kV0, "v2", "", rule);
    write_profiles(fmt::format("{}/pull_{}.csv", dir, tag), q);
    write_tracks(fmt::format("{}/pull_tracks_{}.csv", dir, tag), q);
    total_seconds += q.seconds;
    double worst_fan = 0.0, worst_plateau = 0.0, worst_sigma_pull = 0.0, worst_rho_pull = 0.0;
    for (const Profile& pr : q.profiles) {
      double num = 0.0, den = 0.0, lam = 0.0, sig = 0.0;
      int count = 0;
      const double tail = pull.fan_tail() * pr.t, head = pull.fan_head() * pr.t;
      for (std::size_t k = 0; k < pr.X.size(); ++k) {
        if (pr.X[k] > tail && pr.X[k] < head) {
          num += std::pow(pr.lambda[k] - pr.lambda_exact[k], 2);
          den += std::pow(pr.lambda_exact[k] - 1.0, 2);
        }
        if (pr.X[k] > 0.2 * tail && pr.X[k] < 0.8 * tail) {
          lam += pr.lambda[k];
          sig += pr.sigma[k];
          ++count;
        }
        if (k > 0 && k + 1 < pr.X.size()) {
          worst_rho_pull = std::max(worst_rho_pull, std::abs(pr.rho[k] * pr.lambda[k] / kRho - 1.0));
        }
      }
      worst_fan = std::max(worst_fan, std::sqrt(num / den));
      worst_plateau = std::max(worst_plateau, std::abs(lam / count / pull.lambda_behind() - 1.0));
      worst_sigma_pull = std::max(worst_sigma_pull, std::abs(sig / count / sigma_pull - 1.0));
    }
    {
      Metric fan = metric(row("pull", "fan e2(lambda - 1)"), worst_fan, "<=", 0.03, "");
      if (!fan.pass()) {
        fan.known_deviation =
            "the fan is only 15 dx wide at 0.12 s (dx = 0.05 m); the hourglass control's first-order parts (the "
            "limiter's blend of the simple scheme where the velocity departs from linear, at the fan's head and "
            "tail, and the mean-stress diffusion) round its corners: e2 at 0.12 s 0.20 / 0.13 / 0.075 at dx = 0.05 / "
            "0.025 / 0.0125 m, about dx^0.7 (the rows below; this row is the larger of 0.06 and 0.12 s, when the "
            "fan is narrower still); the Taylor-Galerkin step alone gives 0.20 / 0.13, the simple scheme 0.29 / "
            "0.25";
      }
      rep.metrics.push_back(fan);
    }
    rep.metrics.push_back(
        metric(row("pull", "plateau lambda error"), worst_plateau, "<=", 0.02, ""));
    rep.metrics.push_back(
        metric(row("pull", "plateau sigma error"), worst_sigma_pull, "<=", 0.02, ""));
    rep.metrics.push_back(metric(row("pull", "max |rho lambda / rho0 - 1| (nodes but the ends)"),
                                 worst_rho_pull, "<=", 0.01, ""));
    rep.metrics.push_back(
        metric(row("pull", "mass change sum m / sum m0 - 1"), q.mass_change, "<=", 1e-12, ""));

    // ---- the small-strain solution (V1) of the push: the large-deformation terms are active
    if (dx == 0.05 && fixed) {
      const BarRun s = run_bar(case_file, dx, kV0, "v1");
      write_profiles(fmt::format("{}/push_small_strain_{}.csv", dir, tag), s);
      total_seconds += s.seconds;
      const Profile& big = p.profiles.back();
      const Profile& small = s.profiles.back();
      const double shift = front_position(big, sigma_push) - front_position(small, -kRho * kC0 * kV0);
      const double expected = (push.shock_speed() - kC0) * big.t;
      rep.metrics.push_back(metric("push, dx = 0.05: V2 shock ahead of V1's at 0.12 s / exact difference (S - C0) t",
                                   shift / expected, ">=", 0.5, ""));
      double sig_small = 0.0;
      int count = 0;
      for (std::size_t k = 0; k < small.X.size(); ++k) {
        if (small.X[k] > 0.2 * kC0 * small.t && small.X[k] < 0.8 * kC0 * small.t) {
          sig_small += small.sigma[k];
          ++count;
        }
      }
      rep.metrics.push_back(
          metric("push: V1 (small strain) plateau sigma (linear theory: -rho0 C0 v0 = -2.000 MPa)",
                 sig_small / count, "", 0.0, "Pa"));
    }
  }
  // ---- the fan against the resolution, for each of V2's velocity updates (reported)
  auto fan_error = [&](const BarRun& r) {
    const Profile& pr = r.profiles.back();
    double num = 0.0, den = 0.0;
    for (std::size_t k = 0; k < pr.X.size(); ++k) {
      if (pr.X[k] > pull.fan_tail() * pr.t && pr.X[k] < pull.fan_head() * pr.t) {
        num += std::pow(pr.lambda[k] - pr.lambda_exact[k], 2);
        den += std::pow(pr.lambda_exact[k] - 1.0, 2);
      }
    }
    return std::sqrt(num / den);
  };
  for (double dx : {0.05, 0.025, 0.0125}) {
    for (const char* update : {"simple", "taylor_galerkin", "hourglass"}) {
      if (dx == 0.0125 && !opt.full && std::string(update) != "hourglass") continue;
      const BarRun r = run_bar(case_file, dx, -kV0, "v2", update);
      total_seconds += r.seconds;
      rep.metrics.push_back(metric(fmt::format("pull, dx = {}, velocity update {}: fan e2 at 0.12 s", dx, update),
                                   fan_error(r), "", 0.0, ""));
    }
  }
  rep.notes.push_back(fmt::format("run time of all runs: {:.1f} s", total_seconds));
  std::string note;
  if (opt.plots && run_plot_script("plot_case07.py", dir, note)) {
    rep.plots = {"case07/profiles.png", "case07/tracks.png"};
  } else if (!note.empty()) {
    rep.notes.push_back(note);
  }
  return rep;
}

}  // namespace rktsph::validation
