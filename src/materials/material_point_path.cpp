#include "materials/material_point_path.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "core/error.hpp"

namespace rktsph {

namespace {
LoadPath strain_path(const Sym6& rate) {
  LoadPath p;
  p.rate = rate;
  return p;
}
}  // namespace

LoadPath LoadPath::drained_triaxial(double axial_rate) {
  LoadPath p = strain_path({0.0, axial_rate, 0.0, 0.0, 0.0, 0.0});
  p.control[0] = Control::stress;  // rate 0: constant lateral stress
  p.control[2] = Control::stress;
  return p;
}

LoadPath LoadPath::undrained_triaxial(double axial_rate) {
  return strain_path({-0.5 * axial_rate, axial_rate, -0.5 * axial_rate, 0.0, 0.0, 0.0});
}

LoadPath LoadPath::oedometric(double axial_rate) { return strain_path({0.0, axial_rate, 0.0, 0.0, 0.0, 0.0}); }

LoadPath LoadPath::plane_strain_compression(double axial_rate) {
  LoadPath p = strain_path({0.0, axial_rate, 0.0, 0.0, 0.0, 0.0});
  p.control[0] = Control::stress;
  return p;
}

LoadPath LoadPath::simple_shear(double shear_rate) { return strain_path({0.0, 0.0, 0.0, 0.5 * shear_rate, 0.0, 0.0}); }

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

/// The mixed-control rate: given (sigma, kappa), the rates of (sigma, eps, kappa).
class MixedRate {
 public:
  MixedRate(const Material& m, const LoadPath& path) : material_(m), path_(path) {
    for (int i = 0; i < 6; ++i) {
      (path.control[static_cast<std::size_t>(i)] == Control::stress ? S_ : E_).push_back(i);
    }
    // Constant moduli: D and the inverse of its stress-controlled block once. Pressure-dependent
    // moduli (method-notes eq. (1.8.8)): both at each evaluation, from the current stress.
    const ElasticConstants& el = m.elastic();
    stiffness(el.lambda, el.G, D_, Dss_inv_);
  }

  /// sigma_dot, eps_dot, kappa_dot; with_source = false gives the purely elastic rates.
  void operator()(const Sym6& sigma, const double* k, Sym6& dsig, Sym6& deps, double* dk,
                  bool with_source = true) const {
    if (!material_.pressure_moduli().active()) {
      rate(D_, Dss_inv_, sigma, k, dsig, deps, dk, with_source);
      return;
    }
    const ElasticRate at = material_.elastic_rate().at(sigma.data());
    Mat6 D, Dss_inv;
    stiffness(at.lambda, at.G, D, Dss_inv);
    rate(D, Dss_inv, sigma, k, dsig, deps, dk, with_source);
  }

 private:
  /// D^e (tensor shear: sigma_xy = 2G eps_xy) and the inverse of its stress-controlled block
  /// (at most 6 x 6) in its top-left corner.
  void stiffness(double lambda, double G, Mat6& D, Mat6& Dss_inv) const {
    D.setZero();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) D(i, j) = lambda;
    }
    for (int i = 0; i < 6; ++i) D(i, i) += 2.0 * G;
    const int ns = static_cast<int>(S_.size());
    Dss_inv.setZero();
    if (ns > 0) {
      Eigen::MatrixXd Dss(ns, ns);
      for (int a = 0; a < ns; ++a) {
        for (int b = 0; b < ns; ++b) Dss(a, b) = D(S_[a], S_[b]);
      }
      Dss_inv.topLeftCorner(ns, ns) = Dss.inverse();
    }
  }

  void rate(const Mat6& D, const Mat6& Dss_inv, const Sym6& sigma, const double* k, Sym6& dsig, Sym6& deps, double* dk,
            bool with_source) const {
    Sym6 src{};
    if (with_source) {
      material_.source_rate(sigma, k, src, dk);
    } else {
      for (int j = 0; j < material_.state_size(); ++j) dk[j] = 0.0;
    }
    for (int i : E_) deps[static_cast<std::size_t>(i)] = path_.rate[static_cast<std::size_t>(i)];
    // Stress-controlled components: D_SS eps_S = sigma_dot_S - D_SE eps_E - src_S.
    const int ns = static_cast<int>(S_.size());
    double rhs[6];
    for (int a = 0; a < ns; ++a) {
      const auto ia = static_cast<std::size_t>(S_[a]);
      double r = path_.rate[ia] - src[ia];
      for (int j : E_) r -= D(S_[a], j) * deps[static_cast<std::size_t>(j)];
      rhs[a] = r;
    }
    for (int a = 0; a < ns; ++a) {
      double x = 0.0;
      for (int b = 0; b < ns; ++b) x += Dss_inv(a, b) * rhs[b];
      deps[static_cast<std::size_t>(S_[a])] = x;
    }
    for (int i = 0; i < 6; ++i) {
      double r = src[static_cast<std::size_t>(i)];
      for (int j = 0; j < 6; ++j) r += D(i, j) * deps[static_cast<std::size_t>(j)];
      dsig[static_cast<std::size_t>(i)] = r;
    }
  }

  const Material& material_;
  const LoadPath& path_;
  Mat6 D_;
  std::vector<int> S_, E_;
  Mat6 Dss_inv_;
};

bool finite(const Sym6& a) {
  return std::all_of(a.begin(), a.end(), [](double v) { return std::isfinite(v); });
}

/// One step of the path by backward Euler (method-notes §2.5): the elastic trial of the strain
/// increment, returned by the model; the stress-controlled components' strain increments are
/// found by Newton (forward differences) so that their returned stresses meet the path's.
/// Returns the Newton iterations of the model's returns.
long implicit_path_step(const Material& material, const LoadPath& path, double dt, Sym6& sig, Sym6& eps,
                        std::vector<double>& k) {
  std::vector<int> S, E;
  for (int i = 0; i < 6; ++i) (path.control[static_cast<std::size_t>(i)] == Control::stress ? S : E).push_back(i);
  const ElasticRate el = material.elastic_rate().at(sig.data());
  Mat6 D = Mat6::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) D(i, j) = el.lambda;
  }
  for (int i = 0; i < 6; ++i) D(i, i) += 2.0 * el.G;
  const auto ns = static_cast<int>(S.size());
  Eigen::Matrix<double, 6, 1> de = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i : E) de[i] = path.rate[static_cast<std::size_t>(i)] * dt;
  // First guess of the stress-controlled increments: the elastic partition.
  if (ns > 0) {
    Eigen::MatrixXd Dss(ns, ns);
    Eigen::VectorXd rhs(ns);
    for (int a = 0; a < ns; ++a) {
      double r = path.rate[static_cast<std::size_t>(S[a])] * dt;
      for (int j : E) r -= D(S[a], j) * de[j];
      rhs[a] = r;
      for (int b = 0; b < ns; ++b) Dss(a, b) = D(S[a], S[b]);
    }
    const Eigen::VectorXd x = Dss.lu().solve(rhs);
    for (int a = 0; a < ns; ++a) de[S[a]] = x[a];
  }
  long iterations = 0;
  std::vector<double> k_end(k.size());
  auto returned = [&](const Eigen::Matrix<double, 6, 1>& d, Sym6& out) {
    const Eigen::Matrix<double, 6, 1> ds = D * d;
    Sym6 trial;
    for (std::size_t c = 0; c < 6; ++c) trial[c] = sig[c] + ds[static_cast<Eigen::Index>(c)];
    const ImplicitOutcome o = material.integrate_implicit(trial, k.data(), dt, out, k_end.data());
    iterations += o.iterations;
    if (!o.converged) {
      throw SolverError(fmt::format("material point: the implicit return did not converge (dt = {:.3g} s); "
                                    "reduce path.dt",
                                    dt));
    }
  };
  Sym6 out;
  const double scale = std::max({1.0, std::abs(sig[0]) + std::abs(sig[1]) + std::abs(sig[2]),
                                 material.elastic().E * 1e-9});
  for (int it = 0; it < 30; ++it) {
    returned(de, out);
    if (ns == 0) break;
    Eigen::VectorXd r(ns);
    for (int a = 0; a < ns; ++a) {
      const auto ia = static_cast<std::size_t>(S[a]);
      r[a] = out[ia] - (sig[ia] + path.rate[ia] * dt);
    }
    if (r.lpNorm<Eigen::Infinity>() <= 1e-12 * scale) break;
    Eigen::MatrixXd J(ns, ns);
    const std::vector<double> k_keep = k_end;
    for (int b = 0; b < ns; ++b) {
      Eigen::Matrix<double, 6, 1> dp = de;
      const double h = 1e-7 * std::max(std::abs(de[S[b]]), scale / material.elastic().E);
      dp[S[b]] += h;
      Sym6 op;
      returned(dp, op);
      for (int a = 0; a < ns; ++a) J(a, b) = (op[static_cast<std::size_t>(S[a])] - out[static_cast<std::size_t>(S[a])]) / h;
    }
    k_end = k_keep;
    const Eigen::VectorXd dx = J.lu().solve(-r);
    for (int b = 0; b < ns; ++b) de[S[b]] += dx[b];
    if (it == 29) returned(de, out);
  }
  // The stress-controlled components met to Newton's round-off; set to their targets so that
  // it does not accumulate along the path.
  for (int i : S) sig[static_cast<std::size_t>(i)] += path.rate[static_cast<std::size_t>(i)] * dt;
  for (int i : E) sig[static_cast<std::size_t>(i)] = out[static_cast<std::size_t>(i)];
  k = k_end;
  for (std::size_t c = 0; c < 6; ++c) eps[c] += de[static_cast<Eigen::Index>(c)];
  return iterations;
}

}  // namespace

PathResult integrate_path(const Material& material, const Sym6& sigma0, const LoadPath& path) {
  if (!(path.duration > 0.0)) throw SolverError("material point: duration must be > 0");
  const double dt_nominal = path.dt > 0.0 ? path.dt : path.duration / 1000.0;
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(path.duration / dt_nominal - 1e-9)));
  const int nk = material.state_size();
  const auto unk = static_cast<std::size_t>(nk);
  const MixedRate rate(material, path);

  Sym6 sig = sigma0;
  Sym6 eps{};
  std::vector<double> k(unk);
  material.initial_state(sig, k.data());

  constexpr long kMaxPathSubsteps = 10'000'000;
  PathResult res;
  auto record = [&](double t) { res.points.push_back({t, eps, sig, k}); };
  record(0.0);

  Sym6 ds[4], de[4], sst, dummy;
  std::vector<std::vector<double>> dk(4, std::vector<double>(unk));
  std::vector<double> kt(unk), kel(unk);
  const int every = std::max(1, path.output_every);
  double t = 0.0;
  for (long step = 0; step < nsteps; ++step) {
    const double dt = std::min(dt_nominal, path.duration - t);
    // Stiffness at the start and at the elastic trial end point (method-notes §4.3): inside the
    // surface the rate is 0, but the loading can carry the point outside within the step.
    rate(sig, k.data(), ds[0], dummy, kel.data(), false);
    for (std::size_t c = 0; c < 6; ++c) sst[c] = sig[c] + dt * ds[0][c];
    const double lam = std::max(material.relaxation_rate(sig, k.data()), material.relaxation_rate(sst, k.data()));
    res.max_relaxation_rate = std::max(res.max_relaxation_rate, lam);
    const double want = std::ceil(lam * dt / path.relaxation_target);
    if (material.has_implicit_source() && !(want <= static_cast<double>(Material::max_explicit_substeps))) {
      // Stiff: backward Euler, whatever the fluidity (method-notes §2.5, eq. (2.5.6)).
      res.newton_iterations += implicit_path_step(material, path, dt, sig, eps, k);
      ++res.implicit_steps;
      t = step + 1 == nsteps ? path.duration : t + dt;
      if (!finite(sig) || !finite(eps)) {
        throw SolverError(fmt::format("material point: non-finite stress at t = {:.6g} s", t));
      }
      if ((step + 1) % every == 0 || step + 1 == nsteps) record(t);
      continue;
    }
    if (!(want <= 1e7)) {
      throw SolverError(
          fmt::format("material point: relaxation rate {:.3g} 1/s is too stiff "
                      "for the step {:.3g} s",
                      lam, dt));
    }
    const long nsub = std::max(1L, static_cast<long>(want));
    const double h = dt / static_cast<double>(nsub);
    for (long sub = 0; sub < nsub; ++sub) {
      constexpr double kFrac[4] = {0.0, 0.5, 0.5, 1.0};
      for (int s = 0; s < 4; ++s) {
        for (std::size_t c = 0; c < 6; ++c) sst[c] = s == 0 ? sig[c] : sig[c] + kFrac[s] * h * ds[s - 1][c];
        for (std::size_t j = 0; j < unk; ++j)
          kt[j] = s == 0 ? k[j] : k[j] + kFrac[s] * h * dk[static_cast<std::size_t>(s - 1)][j];
        rate(sst, kt.data(), ds[s], de[s], dk[static_cast<std::size_t>(s)].data());
      }
      for (std::size_t c = 0; c < 6; ++c) {
        sig[c] += h / 6.0 * (ds[0][c] + 2.0 * ds[1][c] + 2.0 * ds[2][c] + ds[3][c]);
        eps[c] += h / 6.0 * (de[0][c] + 2.0 * de[1][c] + 2.0 * de[2][c] + de[3][c]);
      }
      for (std::size_t j = 0; j < unk; ++j) {
        k[j] += h / 6.0 * (dk[0][j] + 2.0 * dk[1][j] + 2.0 * dk[2][j] + dk[3][j]);
      }
    }
    res.substeps += nsub;
    t = step + 1 == nsteps ? path.duration : t + dt;
    // A bound on the whole path's work (the example paths need at most 1.1e6 sub-steps), so that
    // an extreme input fails in seconds instead of running for hours.
    if (res.substeps > kMaxPathSubsteps) {
      throw SolverError(fmt::format(
          "material point: the path needs more than {:.0e} RK4 sub-steps in all (relaxation rate {:.3g} 1/s with "
          "dt = {:.3g} s, by t = {:.6g} s of {:.6g} s); reduce the fluidity or path.dt",
          static_cast<double>(kMaxPathSubsteps), lam, dt, t, path.duration));
    }
    if (!finite(sig) || !finite(eps)) {
      throw SolverError(fmt::format("material point: non-finite stress at t = {:.6g} s", t));
    }
    if ((step + 1) % every == 0 || step + 1 == nsteps) record(t);
  }
  res.steps = nsteps;
  return res;
}

}  // namespace rktsph
