#pragma once
// Backward-Euler (one-stage Radau IIA, L-stable) integration of the Perzyna source over an
// interval tau, the consistent viscoplastic return of method-notes §2.5:
//   sigma = sigma_tr - D^e(sigma) : (dl m(sigma, Y) + dl_t m_t),
//   kappa = kappa_0 + h(dl m + dl_t m_t, kappa),
//   x(sigma, Y)   = Phi^{-1}(dl   / (gamma tau))      (shear mechanism, eq. 2.5.2)
//   x_t(sigma, Y) = Phi^{-1}(dl_t / (gamma tau))      (tension cut-off, when active)
// with sigma_tr the start of the source ODE (plus tau R with the frozen flux). gamma = inf is
// the rate-independent return mapping (x = dead band). Every surface here is an isotropic
// function and the elasticity is isotropic, so sigma stays coaxial with sigma_tr: the unknowns
// are the mean stress, the deviator's components on s_tr and (for Lode-dependent surfaces) on
// dev(s_tr^2), the history variable that sets Y, and the multipliers (eq. 2.5.3). Newton with
// the exact Jacobian of each surface's (p', q) or (p', q, theta) form (eqs. (2.5.8)–(2.5.16)), or
// with forward differences in the generic problem (the reference, and the fall-back), a
// backtracking line search, an active set for the two mechanisms, and halving of the interval
// when Newton fails: a few iterations whatever gamma and the cohesion.
#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <type_traits>
#include <utility>

#include "core/types.hpp"
#include "materials/lode_form.hpp"
#include "materials/material.hpp"
#include "materials/overstress.hpp"
#include "materials/pq_form.hpp"
#include "materials/tension_cutoff.hpp"
#include "materials/tensor.hpp"

namespace rktsph::detail {

/// Phi^{-1}(y) for the overstress function, continued linearly below y = 0 so that Newton may
/// cross it (the active set then drops the mechanism), and its derivative (eq. 2.5.2).
struct OverstressInverse {
  const Overstress& phi;
  double gamma_tau;  // gamma tau; +inf: rate independent

  double value(double dl) const {
    if (std::isinf(gamma_tau)) return phi.dead_band;
    const double y = dl / gamma_tau;
    if (y <= 0.0) return phi.dead_band + y * slope_at_zero();
    return std::max(phi.dead_band, continuous_inverse(y));
  }
  double derivative(double dl) const {
    if (std::isinf(gamma_tau)) return 0.0;
    const double y = dl / gamma_tau;
    if (y <= 0.0) return slope_at_zero() / gamma_tau;
    const double x = continuous_inverse(y);
    if (x < phi.dead_band) return 0.0;
    return 1.0 / (phi.slope(std::max(x, 1e-300)) * gamma_tau);
  }

 private:
  double continuous_inverse(double y) const {
    if (phi.kind == OverstressKind::power) return phi.exponent == 1.0 ? y : std::pow(y, 1.0 / phi.exponent);
    return std::log1p(y) / phi.exponent;
  }
  double slope_at_zero() const {
    // dx/dy at y = 0+: 1 for N = 1 or the exponential law (1/N); a power N < 1 has 0 there, N > 1 infinity.
    if (phi.kind == OverstressKind::power) return phi.exponent <= 1.0 ? 1.0 : 1e3;
    return 1.0 / phi.exponent;
  }
};

/// The backward-Euler return of one Perzyna model. `Model` gives the parts: surface(),
/// hardening(), overstress(), fluidity(), tension_cutoff() and apply_elastic(sigma, eps).
template <class Model>
class PerzynaBackwardEuler {
 public:
  using Hardening = std::remove_cvref_t<decltype(std::declval<const Model&>().hardening())>;
  static constexpr int kStates = Hardening::kSize;
  static constexpr int kMaxUnknowns = 7;  // mean, a, b, kappa, dl, dl_t
  static constexpr int kMaxIterations = 40;
  static constexpr double kTolerance = 1e-12;  // scaled residual, infinity norm
  static constexpr double kRoundOffTolerance = 1e-9;  // accepted where Newton stalls on round-off
  static constexpr double kAddTolerance = 1e-9;  // overstress that brings a mechanism back
  // Where the apex flow is evaluated, as a fraction of the trial scale.
  static constexpr double kApexOffset = 1e-6;
  static constexpr double kRoot32 = 1.2247448713915890491;   // sqrt(3/2): q = sqrt(3/2) |s|
  static constexpr double kRoot23 = 0.81649658092772603273;  // sqrt(2/3)

  /// Which reduced problem solve() uses: the fastest the surface allows ((p', q) or (p', q,
  /// theta) with the exact Jacobian, the latter falling back on the generic one where it fails),
  /// the same without that fall-back (for the tests), or the generic (mean, a, b) one with
  /// forward differences, the reference of the tests and the benchmark.
  enum class Path { fastest, exact_only, generic };

  explicit PerzynaBackwardEuler(const Model& model, Path path = Path::fastest) : model_(model), path_(path) {}

  /// Integrate from the trial state (sigma_tr, k0) over tau; sigma and k receive the end state.
  /// On failure (no convergence) sigma and k are left at the trial state and converged = false.
  ImplicitOutcome solve(const Sym6& sigma_tr, const double* k0, double tau, Sym6& sigma, double* k) const {
    const Hardening& hard = model_.hardening();
    const Overstress& phi = model_.overstress();
    const TensionCutoff& cut = model_.tension_cutoff();
    sigma = sigma_tr;
    for (int j = 0; j < kStates; ++j) k[j] = k0[j];
    const double Y0 = hard.size(k0);
    const double xt_tr = cut.active ? cut.overstress(sigma_tr, Y0) : -1.0;
    const bool tension = cut.active && xt_tr > phi.dead_band;
    ImplicitOutcome out;
    if (path_ != Path::generic) {
      if constexpr (requires(const Surface& s) { s.pq_theta(0.0, 0.0, LodeAngle{}, 1.0); }) {
        if (model_.surface().lode_depends()) {
          // The trial's overstress from the form, the invariants it has computed anyway.
          LodeProblem pb(model_, sigma_tr, k0, tau);
          const bool shear = pb.trial_overstress() > phi.dead_band;
          if (!shear && !tension) {
            out.converged = true;
            return out;
          }
          out = active_set(pb, shear, tension, sigma, k);
          if (out.converged || path_ == Path::exact_only) return out;
          // A trial far outside (10^3 times the strength) can have several Lode angles whose
          // flow points back at it, and Newton on these coordinates may stall between them:
          // the generic problem's path then (method-notes §2.5, "(p', q, theta) form").
        }
      }
    }
    const bool shear = model_.surface().value(sigma_tr, Y0) / Y0 - 1.0 > phi.dead_band;
    if (!shear && !tension) {
      out.converged = true;
      return out;
    }
    if (path_ != Path::generic) {
      if constexpr (requires(const Surface& s) { s.pq(0.0, 0.0, 1.0); }) {
        if (!model_.surface().lode_depends()) {
          PQProblem pb(model_, sigma_tr, k0, tau);
          return active_set(pb, shear, tension, sigma, k);
        }
      }
    }
    Problem pb(model_, sigma_tr, k0, tau);
    const int tried = out.iterations;
    out = active_set(pb, shear, tension, sigma, k);
    out.iterations += tried;
    return out;
  }

 private:
  using Surface = std::remove_cvref_t<decltype(std::declval<const Model&>().surface())>;

  // Active set (eq. 2.5.4) over one of the problems below: a mechanism whose multiplier ends
  // negative is dropped, one whose overstress ends above its consistency value is added.
  template <class P>
  ImplicitOutcome active_set(P& pb, bool shear, bool tension, Sym6& sigma, double* k) const {
    const Overstress& phi = model_.overstress();
    const TensionCutoff& cut = model_.tension_cutoff();
    ImplicitOutcome out;
    const bool inert = pb.shear_inert();
    shear = shear && !inert;
    if (!shear && !tension) {
      out.converged = true;
      return out;
    }
    for (int pass = 0; pass < 4; ++pass) {
      ImplicitOutcome o = pb.newton(shear, tension);
      out.iterations += o.iterations;
      if (o.converged && pb.at_apex() && pb.apex_inside()) {
        pb.forbid_apex();
        o = pb.newton(shear, tension);
        out.iterations += o.iterations;
      }
      if (!o.converged) return out;
      const bool drop_shear = shear && pb.dl < 0.0;
      const bool drop_tension = tension && pb.dl_t < 0.0;
      bool changed = drop_shear || drop_tension;
      shear = shear && !drop_shear;
      tension = tension && !drop_tension;
      if (!changed) {
        const double Y = pb.size();
        const Sym6 sig = pb.sigma();
        const bool add_shear =
            !shear && !inert && model_.surface().value(sig, Y) / Y - 1.0 > phi.dead_band + kAddTolerance;
        const bool add_tension = cut.active && !tension && cut.overstress(sig, Y) > phi.dead_band + kAddTolerance;
        changed = add_shear || add_tension;
        shear = shear || add_shear;
        tension = tension || add_tension;
      }
      if (!changed) {
        pb.finish(sigma, k);
        out.converged = true;
        return out;
      }
      if (!shear && !tension) {  // elastic after all
        out.converged = true;
        return out;
      }
    }
    return out;
  }

  // A few unknowns: fixed storage, no allocation, a size carried beside it.
  struct Vector {
    std::array<double, kMaxUnknowns> v{};
    int n = 0;
    explicit Vector(int size = 0) : n(size) {}
    int size() const { return n; }
    double& operator[](int i) { return v[static_cast<std::size_t>(i)]; }
    double operator[](int i) const { return v[static_cast<std::size_t>(i)]; }
    double norm_inf() const {
      double m = 0.0;
      for (int i = 0; i < n; ++i) m = std::max(m, std::abs(v[static_cast<std::size_t>(i)]));
      return m;
    }
    double squared_norm() const {
      double m = 0.0;
      for (int i = 0; i < n; ++i) m += v[static_cast<std::size_t>(i)] * v[static_cast<std::size_t>(i)];
      return m;
    }
  };
  struct Matrix {
    std::array<double, kMaxUnknowns * kMaxUnknowns> a{};
    double& operator()(int i, int j) { return a[static_cast<std::size_t>(i * kMaxUnknowns + j)]; }
    double operator()(int i, int j) const { return a[static_cast<std::size_t>(i * kMaxUnknowns + j)]; }
    void clear(int n) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) (*this)(i, j) = 0.0;
      }
    }
  };

  // Solve J x = -r by Gaussian elimination with partial pivoting; false if singular.
  static bool solve_negated(Matrix J, Vector r, Vector& x) { return solve_negated_in_place(J, r, x); }
  // Solve J x = -r by Gaussian elimination with partial pivoting, overwriting J and r; false
  // if singular.
  static bool solve_negated_in_place(Matrix& J, Vector& r, Vector& x) {
    const int n = r.size();
    for (int c = 0; c < n; ++c) {
      int piv = c;
      for (int i = c + 1; i < n; ++i) {
        if (std::abs(J(i, c)) > std::abs(J(piv, c))) piv = i;
      }
      if (!(std::abs(J(piv, c)) > 0.0)) return false;
      if (piv != c) {
        for (int j = c; j < n; ++j) std::swap(J(c, j), J(piv, j));
        std::swap(r[c], r[piv]);
      }
      const double inv = 1.0 / J(c, c);
      for (int i = c + 1; i < n; ++i) {
        const double f = J(i, c) * inv;
        for (int j = c + 1; j < n; ++j) J(i, j) -= f * J(c, j);
        r[i] -= f * r[c];
      }
    }
    x = Vector(n);
    for (int i = n - 1; i >= 0; --i) {
      double sum = -r[i];
      for (int j = i + 1; j < n; ++j) sum -= J(i, j) * x[j];
      x[i] = sum / J(i, i);
      if (!std::isfinite(x[i])) return false;
    }
    return true;
  }

  // solve_negated_in_place with the size known at compile time: unrolled, and the pivots'
  // reciprocals reused by the back-substitution (the Lode problem's few unknowns; its results
  // differ from the general routine's in the last bits only).
  template <int N>
  static bool solve_fixed(Matrix& J, Vector& r, Vector& x) {
    double inv_pivot[N];
    for (int c = 0; c < N; ++c) {
      int piv = c;
      for (int i = c + 1; i < N; ++i) {
        if (std::abs(J(i, c)) > std::abs(J(piv, c))) piv = i;
      }
      if (!(std::abs(J(piv, c)) > 0.0)) return false;
      if (piv != c) {
        for (int j = c; j < N; ++j) std::swap(J(c, j), J(piv, j));
        std::swap(r[c], r[piv]);
      }
      inv_pivot[c] = 1.0 / J(c, c);
      for (int i = c + 1; i < N; ++i) {
        const double f = J(i, c) * inv_pivot[c];
        for (int j = c + 1; j < N; ++j) J(i, j) -= f * J(c, j);
        r[i] -= f * r[c];
      }
    }
    x = Vector(N);
    bool finite = true;
    for (int i = N - 1; i >= 0; --i) {
      double sum = -r[i];
      for (int j = i + 1; j < N; ++j) sum -= J(i, j) * x[j];
      x[i] = sum * inv_pivot[i];
      finite = finite && std::isfinite(x[i]);
    }
    return finite;
  }
  static bool solve_small(Matrix& J, Vector& r, Vector& x) {
    switch (r.size()) {
      case 2:
        return solve_fixed<2>(J, r, x);
      case 3:
        return solve_fixed<3>(J, r, x);
      case 4:
        return solve_fixed<4>(J, r, x);
      case 5:
        return solve_fixed<5>(J, r, x);
      case 6:
        return solve_fixed<6>(J, r, x);
      default:
        return solve_negated_in_place(J, r, x);
    }
  }

  // The reduced problem of one trial state (eq. 2.5.3). Unknowns, in order: the mean stress,
  // the deviator's components a (on s_tr) and b (on the Lode direction) unless the deviator is
  // held at the apex, the history variable that sets Y, and the active multipliers. Rows: the
  // mean, a and b (or, at the apex, a alone), the history, the shear consistency (not at the
  // apex) and the tension consistency.
  class Problem {
   public:
    Problem(const Model& model, const Sym6& sigma_tr, const double* k0, double tau)
        : model_(model), inverse_{model.overstress(), model.fluidity() * tau} {
      for (int j = 0; j < kStates; ++j) k0_[j] = k0[j];
      mean_tr_ = tensor::trace(sigma_tr) / 3.0;
      const Sym6 s = tensor::deviator(sigma_tr);
      const double ns = std::sqrt(tensor::ddot(s, s));
      scale_ = std::max({model.hardening().size(k0), ns, std::abs(mean_tr_)});
      multiplier_scale_ = scale_ / model.elastic().E;
      if (ns > 1e-13 * scale_) {
        has_a_ = true;
        e1_ = tensor::scaled(s, 1.0 / ns);
        a_tr_ = ns;
        if (model.surface().lode_depends()) {
          // The second direction of the coaxial deviatoric plane: dev(s^2) without its part on s.
          Sym6 t = tensor::deviator(tensor::square(s));
          const double along = tensor::ddot(t, e1_);
          for (std::size_t i = 0; i < 6; ++i) t[i] -= along * e1_[i];
          const double nt = std::sqrt(tensor::ddot(t, t));
          if (nt > 1e-8 * ns * ns) {
            has_b_ = true;
            e2_ = tensor::scaled(t, 1.0 / nt);
          }
        }
      }
      state_.mean = mean_tr_;
      state_.a = a_tr_;
      state_.kd = k0_[Hardening::kDriver];
    }

    double dl = 0.0, dl_t = 0.0;

    /// A hydrostatic trial whose potential has no volumetric part (psi = 0): the shear mechanism
    /// cannot act on it at all, whatever its overstress (method-notes eq. (2.5.5)).
    bool shear_inert() const {
      if (has_a_) return false;
      const Sym6 m = model_.surface().flow(sigma(), size());
      return std::abs(tensor::trace(m)) <= 1e-12 * (1.0 + std::sqrt(tensor::ddot(m, m)));
    }

    Sym6 sigma() const { return stress(state_.mean, state_.a, state_.b); }
    double size() const { return size_at(state_.kd); }

    /// Newton on the active mechanisms from the current iterate (eq. 2.5.3).
    ImplicitOutcome newton(bool shear, bool tension) {
      shear_ = shear;
      tension_ = tension;
      apex_ = false;
      if (!shear_) dl = 0.0;
      if (!tension_) dl_t = 0.0;
      if (shear_ && dl <= 0.0) {
        dl = first_multiplier();
        // The history consistent with that guess.
        double kk[kStates];
        model_.hardening().increment(tensor::scaled(model_.surface().flow(sigma(), size()), dl), k0_, kk);
        state_.kd = kk[Hardening::kDriver];
      }
      state_scale_ = std::max({std::abs(k0_[Hardening::kDriver]), std::abs(state_.kd), Hardening::kDriverScale});
      ImplicitOutcome out;
      Vector z = unknowns();
      Vector r = residual(z);
      double merit = r.squared_norm();
      int clamps = 0;
      for (int it = 0; it < kMaxIterations; ++it) {
        if (r.norm_inf() <= kTolerance) {
          out.converged = true;
          return out;
        }
        ++out.iterations;
        Vector dz;
        const bool solved = solve_negated(jacobian(z, r), r, dz);
        const bool at_axis =
            deviator_free() && shear_ && allow_apex_ && !apex_ && (z[1] == 0.0 || (solved && z[1] + dz[1] < 0.0));
        if (!solved && !at_axis) return out;
        // Backtracking: halve until the scaled residual decreases.
        double alpha = 1.0;
        Vector z_new = z, r_new = r;
        double merit_new = merit;
        bool clamped = false, decreased = false;
        for (int ls = 0; ls < 12 && solved && !decreased; ++ls) {
          for (int i = 0; i < z.size(); ++i) z_new[i] = z[i] + alpha * dz[i];
          clamped = clamp(z_new);
          r_new = residual(z_new);
          merit_new = r_new.squared_norm();
          decreased = std::isfinite(merit_new) && merit_new < (1.0 - 1e-4 * alpha) * merit;
          if (!decreased) alpha *= 0.5;
        }
        if (!decreased && at_axis) {
          // Newton drives the deviator through zero and no shorter step helps: the apex.
          enter_apex();
          z = unknowns();
          r = residual(z);
          merit = r.squared_norm();
          continue;
        }
        if (!decreased) {
          // No step lowers the residual: round-off (the stress's largest component over the
          // deviator's size) when it is already small, a failure otherwise.
          out.converged = r.norm_inf() <= kRoundOffTolerance;
          return out;
        }
        set(z_new);
        if (clamped && shear_ && ++clamps >= 2 && !apex_ && allow_apex_) enter_apex();
        z = unknowns();
        r = residual(z);
        merit = r.squared_norm();
      }
      out.converged = r.norm_inf() <= kTolerance;
      return out;
    }

    /// Whether the return ended at the apex, and whether the surface holds there with room to
    /// spare (then the true return has a deviator left: retry without the apex).
    bool at_apex() const { return apex_; }
    bool apex_inside() const {
      const Sym6 sig = sigma();
      const double Y = size();
      return model_.surface().value(sig, Y) / Y - 1.0 < inverse_.value(dl) - 1e-9;
    }
    void forbid_apex() {
      allow_apex_ = false;
      apex_ = false;
      state_.mean = mean_tr_;
      state_.a = a_tr_;
      state_.b = 0.0;
      state_.kd = k0_[Hardening::kDriver];
      dl = 0.0;
      dl_t = 0.0;
    }

    void finish(Sym6& sigma_out, double* k) const {
      sigma_out = sigma();
      const Sym6 e = plastic_strain(state_, dl, dl_t);
      model_.hardening().increment(e, k0_, k);
      k[Hardening::kDriver] = state_.kd;
    }

   private:
    struct State {
      double mean = 0.0, a = 0.0, b = 0.0, kd = 0.0;
    };

    // The deviator is driven through zero: the apex of a potential without deviatoric
    // rounding. Hold it at zero; its row fixes the multiplier (method-notes eq. (2.5.5)).
    void enter_apex() {
      apex_ = true;
      state_.a = 0.0;
      state_.b = 0.0;
    }

    bool deviator_free() const { return has_a_ && !apex_; }
    int count() const {
      return 2 + (deviator_free() ? 1 + (has_b_ ? 1 : 0) : 0) + (shear_ ? 1 : 0) + (tension_ ? 1 : 0);
    }

    Vector unknowns() const {
      Vector z(count());
      int i = 0;
      z[i++] = state_.mean;
      if (deviator_free()) {
        z[i++] = state_.a;
        if (has_b_) z[i++] = state_.b;
      }
      z[i++] = state_.kd;
      if (shear_) z[i++] = dl;
      if (tension_) z[i++] = dl_t;
      return z;
    }
    // The iterate of z; the multipliers through the out-parameters.
    State unpack(const Vector& z, double& l, double& lt) const {
      State st;
      int i = 0;
      st.mean = z[i++];
      if (deviator_free()) {
        st.a = z[i++];
        if (has_b_) st.b = z[i++];
      }
      st.kd = z[i++];
      l = shear_ ? z[i++] : 0.0;
      lt = tension_ ? z[i++] : 0.0;
      return st;
    }
    void set(const Vector& z) { state_ = unpack(z, dl, dl_t); }
    // The deviator's size along s_tr stays >= 0 (a flip through the axis is not a return).
    bool clamp(Vector& z) const {
      if (!deviator_free() || z[1] >= 0.0) return false;
      z[1] = 0.0;
      if (has_b_) z[2] = 0.0;
      return true;
    }

    Sym6 stress(double mean, double a, double b) const {
      Sym6 s{};
      for (std::size_t i = 0; i < 6; ++i) s[i] = a * e1_[i] + b * e2_[i];
      for (std::size_t i = 0; i < 3; ++i) s[i] += mean;
      return s;
    }
    void states(double kd, double* kk) const {
      for (int j = 0; j < kStates; ++j) kk[j] = k0_[j];
      kk[Hardening::kDriver] = kd;
    }
    double size_at(double kd) const {
      double kk[kStates];
      states(kd, kk);
      return model_.hardening().size(kk);
    }
    // dl m + dl_t m_t. At the apex the flow is the limit of m as the deviator vanishes along s_tr
    // (a sub-gradient: the surfaces' guards give none exactly on the axis).
    Sym6 plastic_strain(const State& st, double l, double lt) const {
      Sym6 e{};
      const double Y = size_at(st.kd);
      if (shear_ && l != 0.0) {
        // At a = 0 exactly the flow of a potential without deviatoric rounding is undefined (the
        // surfaces give none): it is taken as its limit along s_tr, so Newton sees it continuous.
        const double a = apex_ || !has_a_ ? kApexOffset * scale_ * (has_a_ ? 1.0 : 0.0) : std::max(st.a, kApexOffset * scale_);
        e = tensor::scaled(model_.surface().flow(stress(st.mean, a, st.b), Y), l);
      }
      if (tension_ && lt != 0.0) {
        for (std::size_t i = 0; i < 3; ++i) e[i] += lt / 3.0;
      }
      return e;
    }

    // A rate-independent linearised guess (eq. 2.5.5): x_tr / (stiffness/Y + 1/(gamma tau)).
    double first_multiplier() const {
      const Sym6 sig = sigma();
      const double Y = size();
      const double x = model_.surface().value(sig, Y) / Y - 1.0;
      const Sym6 n = model_.surface().gradient(sig, Y);
      const Sym6 m = model_.surface().flow(sig, Y);
      const double stiff = std::abs(tensor::ddot(n, model_.apply_elastic(sig, m))) / Y;
      const double soft = std::isinf(inverse_.gamma_tau) ? 0.0 : 1.0 / inverse_.gamma_tau;
      return std::max(0.0, x - model_.overstress().dead_band) / std::max(stiff + soft, 1e-300);
    }

    // Residuals, scaled: stresses by the trial scale, the history by its own scale, the
    // consistency conditions (overstress times Y) by the trial scale too, since F is computed
    // from the stress with the round-off of its largest component.
    Vector residual(const Vector& z) const {
      double l = 0.0, lt = 0.0;
      const State st = unpack(z, l, lt);
      const Sym6 sig = stress(st.mean, st.a, st.b);
      double kk[kStates];
      states(st.kd, kk);
      const double Y = model_.hardening().size(kk);
      const Sym6 e = plastic_strain(st, l, lt);
      const Sym6 de = model_.apply_elastic(sig, e);
      double k_end[kStates];
      model_.hardening().increment(e, k0_, k_end);
      Vector r(z.size());
      int j = 0;
      const PressureDependentModuli& moduli = model_.pressure_moduli();
      const double mean_end = moduli.active()
                                  ? -moduli.pressure_after_plastic_volume(-mean_tr_, tensor::trace(e))
                                  : mean_tr_ - tensor::trace(de) / 3.0;
      r[j++] = (st.mean - mean_end) / scale_;
      if (deviator_free()) {
        r[j++] = (st.a - a_tr_ + tensor::ddot(de, e1_)) / scale_;
        if (has_b_) r[j++] = (st.b + tensor::ddot(de, e2_)) / scale_;
      }
      r[j++] = (st.kd - k_end[Hardening::kDriver]) / state_scale_;
      if (shear_) {
        r[j++] = apex_ ? (tensor::ddot(de, e1_) - a_tr_) / scale_
                       : (model_.surface().value(sig, Y) / Y - 1.0 - inverse_.value(l)) * Y / scale_;
      }
      if (tension_) r[j++] = (model_.tension_cutoff().overstress(sig, Y) - inverse_.value(lt)) * Y / scale_;
      return r;
    }

    // Forward differences, each unknown stepped by 1e-7 of its scale.
    Matrix jacobian(const Vector& z, const Vector& r) const {
      const int n = z.size();
      const int history = deviator_free() ? 2 + (has_b_ ? 1 : 0) : 1;
      Matrix J{};
      for (int c = 0; c < n; ++c) {
        double scale = scale_;
        if (c == history) scale = state_scale_;
        if (c > history) scale = std::max(std::abs(z[c]), multiplier_scale_);
        const double h = 1e-7 * scale;
        Vector zp = z;
        zp[c] += h;
        const Vector rp = residual(zp);
        for (int row = 0; row < n; ++row) J(row, c) = (rp[row] - r[row]) / h;
      }
      return J;
    }

    const Model& model_;
    OverstressInverse inverse_;
    double k0_[kStates];
    double mean_tr_ = 0.0, a_tr_ = 0.0, scale_ = 1.0, multiplier_scale_ = 1.0;
    Sym6 e1_{}, e2_{};
    bool has_a_ = false, has_b_ = false, apex_ = false, allow_apex_ = true;
    bool shear_ = false, tension_ = false;
    State state_;
    double state_scale_ = 1.0;  // of the history row, fixed for one Newton solve
  };

  // The return of a Lode-independent surface in the (p', q) plane with its exact Jacobian
  // (method-notes eqs. (2.5.8)–(2.5.10)): unknowns p', q (unless the trial is hydrostatic or the
  // deviator is held at the apex), the driver of Y and the active multipliers; rows the p' and
  // q equations (at the apex the q equation replaces the shear consistency), the driver and
  // the consistency conditions. The deviator keeps the trial's direction.
  class PQProblem {
   public:
    PQProblem(const Model& model, const Sym6& sigma_tr, const double* k0, double tau)
        : model_(model), inverse_{model.overstress(), model.fluidity() * tau}, sigma_tr_(sigma_tr) {
      for (int j = 0; j < kStates; ++j) k0_[j] = k0[j];
      const Invariants inv = invariants(sigma_tr);
      p_tr_ = inv.p;
      q_tr_ = inv.q;
      scale_ = std::max({model.hardening().size(k0), q_tr_, std::abs(p_tr_)});
      has_q_ = q_tr_ > 1e-13 * scale_;
      p_ = p_tr_;
      q_ = q_tr_;
      kd_ = k0_[Hardening::kDriver];
      const PressureDependentModuli& pm = model.pressure_moduli();
      if (!pm.active()) {
        K_ = model.elastic().K;
        G_ = model.elastic().G;
      }
    }

    double dl = 0.0, dl_t = 0.0;

    bool shear_inert() const {
      if (has_q_) return false;
      return model_.surface().pq(p_, 0.0, size()).Q_p == 0.0;
    }
    bool at_apex() const { return apex_; }
    bool apex_inside() const {
      const double Y = size();
      return model_.surface().pq(p_, q_, Y).F / Y - 1.0 < inverse_.value(dl) - 1e-9;
    }
    void forbid_apex() {
      allow_apex_ = false;
      apex_ = false;
      p_ = p_tr_;
      q_ = q_tr_;
      kd_ = k0_[Hardening::kDriver];
      dl = dl_t = 0.0;
    }
    double size() const { return model_.hardening().size_of(kd_); }
    Sym6 sigma() const {
      const double ratio = has_q_ ? q_ / q_tr_ : 0.0;
      const double mean_tr = -p_tr_;
      Sym6 s;
      for (std::size_t i = 0; i < 6; ++i) s[i] = ratio * (sigma_tr_[i] - (i < 3 ? mean_tr : 0.0));
      for (std::size_t i = 0; i < 3; ++i) s[i] -= p_;
      return s;
    }

    ImplicitOutcome newton(bool shear, bool tension) {
      shear_ = shear;
      tension_ = tension;
      apex_ = false;
      if (!shear_) dl = 0.0;
      if (!tension_) dl_t = 0.0;
      if (shear_ && dl <= 0.0) {
        // A linearised guess (eq. 2.5.5) and the driver it gives.
        const double Y = size();
        const PQForm f = model_.surface().pq(p_, q_, Y);
        const double stiff = std::abs(-f.F_p * K() * f.Q_p + 3.0 * G() * f.F_q * f.Q_q) / Y;
        const double soft = std::isinf(inverse_.gamma_tau) ? 0.0 : 1.0 / inverse_.gamma_tau;
        dl = std::max(0.0, f.F / Y - 1.0 - model_.overstress().dead_band) / std::max(stiff + soft, 1e-300);
        kd_ = model_.hardening().driver_end(k0_[Hardening::kDriver], dl, f.Q_p, f.Q_q, dl_t).value;
      }
      state_scale_ = std::max({std::abs(k0_[Hardening::kDriver]), std::abs(kd_), Hardening::kDriverScale});
      ImplicitOutcome out;
      Vector z = unknowns();
      Matrix Ja, Jb;  // the Jacobian at z, and at the line search's trial point
      Matrix* J = &Ja;
      Matrix* J_new = &Jb;
      Vector r = evaluate(z, J);
      for (int it = 0; it < kMaxIterations; ++it) {
        if (r.norm_inf() <= kTolerance) {
          out.converged = true;
          return out;
        }
        ++out.iterations;
        Vector dz, rr = r;
        const double merit = r.squared_norm();
        const bool solved = solve_negated_in_place(*J, rr, dz);  // *J is spent: re-evaluated below
        // Newton drives q through zero, or q already sits clamped at zero (where the
        // consistency row of a potential without rounding is singular).
        const bool at_axis =
            has_q_ && !apex_ && shear_ && allow_apex_ && (z[1] == 0.0 || (solved && z[1] + dz[1] < 0.0));
        if (!solved && !at_axis) return out;
        double alpha = 1.0;
        Vector z_new = z;
        Vector r_new;
        bool decreased = false;
        for (int ls = 0; ls < 12 && solved && !decreased; ++ls) {
          for (int i = 0; i < z.size(); ++i) z_new[i] = z[i] + alpha * dz[i];
          if (has_q_ && !apex_ && z_new[1] < 0.0) z_new[1] = 0.0;  // q >= 0
          r_new = evaluate(z_new, J_new);
          const double m = r_new.squared_norm();
          decreased = std::isfinite(m) && m < (1.0 - 1e-4 * alpha) * merit;
          if (!decreased) alpha *= 0.5;
        }
        if (!decreased && at_axis) {
          // Newton drives q through zero and no shorter step helps: the apex (eq. 2.5.5).
          apex_ = true;
          q_ = 0.0;
          z = unknowns();
          r = evaluate(z, J);
          continue;
        }
        if (!decreased) {
          out.converged = r.norm_inf() <= kRoundOffTolerance;
          return out;
        }
        z = z_new;
        r = r_new;
        std::swap(J, J_new);
        set(z);
      }
      out.converged = r.norm_inf() <= kTolerance;
      return out;
    }

    void finish(Sym6& sigma_out, double* k) const {
      sigma_out = sigma();
      // The full history from the plastic strain dl m + dl_t/3 1 (eq. 2.5.1): its deviatoric
      // equivalent is dl Q_q, its volume -dl Q_p + dl_t.
      const PQForm f = model_.surface().pq(p_, apex_ ? 0.0 : q_, size());
      model_.hardening().pq_states(k0_, shear_ ? dl : 0.0, f.Q_p, f.Q_q, tension_ ? dl_t : 0.0, k);
      k[Hardening::kDriver] = kd_;
    }

   private:
    double K() const { return K_ > 0.0 ? K_ : model_.pressure_moduli().bulk_modulus(p_); }
    double G() const { return G_ > 0.0 ? G_ : model_.pressure_moduli().shear_modulus(K()); }

    bool q_free() const { return has_q_ && !apex_; }
    int count() const { return 2 + (q_free() ? 1 : 0) + (shear_ ? 1 : 0) + (tension_ ? 1 : 0); }
    Vector unknowns() const {
      Vector z(count());
      int i = 0;
      z[i++] = p_;
      if (q_free()) z[i++] = q_;
      z[i++] = kd_;
      if (shear_) z[i++] = dl;
      if (tension_) z[i++] = dl_t;
      return z;
    }
    void set(const Vector& z) {
      int i = 0;
      p_ = z[i++];
      if (q_free()) q_ = z[i++];
      kd_ = z[i++];
      if (shear_) dl = z[i++];
      if (tension_) dl_t = z[i++];
    }

    // Residuals (scaled as the generic problem's) and, when J is given, their exact Jacobian.
    Vector evaluate(const Vector& z, Matrix* J) const {
      int i = 0;
      const double p = z[i++];
      const int iq = q_free() ? i++ : -1;
      const double q = iq >= 0 ? z[iq] : 0.0;
      const int ik = i++;
      const double kd = z[ik];
      const int il = shear_ ? i++ : -1;
      const int it = tension_ ? i++ : -1;
      const double l = il >= 0 ? z[il] : 0.0;
      const double lt = it >= 0 ? z[it] : 0.0;
      const Hardening& hard = model_.hardening();
      const double Y = hard.size_of(kd), Yk = hard.size_slope(kd);
      // At the apex the flow is its limit along the deviator (q -> 0+).
      const PQForm f = model_.surface().pq(p, q, Y);
      const double Qp = shear_ ? f.Q_p : 0.0, Qq = shear_ ? f.Q_q : 0.0;
      const double ev = -l * Qp + lt;  // plastic volumetric strain, dilation positive
      // p' after ev: K ev at constant moduli, the exact swelling law with p'-dependent ones.
      const PressureDependentModuli& pm = model_.pressure_moduli();
      double p_end = 0.0, dp_dev = 0.0, G = G_, dG_dp = 0.0;
      if (pm.active()) {
        p_end = pm.pressure_after_plastic_volume(p_tr_, ev);
        dp_dev = pm.v0_over_kappa * std::clamp(p_end, pm.p_min, pm.p_max);
        const double Kp = pm.bulk_modulus(p);
        G = pm.shear_modulus(Kp);
        const bool inside = p > pm.p_min && p < pm.p_max;
        dG_dp = pm.constant_shear || !inside ? 0.0 : pm.G_over_K * pm.v0_over_kappa;
      } else {
        p_end = p_tr_ + K_ * ev;
        dp_dev = K_;
      }
      const auto dEnd = hard.driver_end(k0_[Hardening::kDriver], l, Qp, Qq, lt);
      const int n = z.size();
      Vector r(n);
      int row = 0;
      const double s = scale_, ss = state_scale_;
      // d ev / d(p, q, kd, l, lt)
      const double ev_p = -l * f.Q_pp * (shear_ ? 1.0 : 0.0), ev_q = -l * f.Q_pq * (shear_ ? 1.0 : 0.0);
      const double ev_k = -l * f.Q_pY * Yk * (shear_ ? 1.0 : 0.0), ev_l = -Qp, ev_lt = 1.0;
      auto put = [&](int rr, int c, double v) {
        if (J != nullptr && c >= 0) (*J)(rr, c) = v;
      };
      if (J != nullptr) J->clear(n);
      // p' row
      r[row] = (p - p_end) / s;
      put(row, 0, (1.0 - dp_dev * ev_p) / s);
      put(row, iq, -dp_dev * ev_q / s);
      put(row, ik, -dp_dev * ev_k / s);
      put(row, il, -dp_dev * ev_l / s);
      put(row, it, -dp_dev * ev_lt / s);
      ++row;
      // q row (or, at the apex, the deviator's return in place of the consistency below)
      auto q_row = [&](int rr) {
        r[rr] = (q - q_tr_ + 3.0 * G * l * Qq) / s;
        put(rr, 0, (3.0 * dG_dp * l * Qq + 3.0 * G * l * f.Q_pq) / s);
        put(rr, iq, (1.0 + 3.0 * G * l * f.Q_qq) / s);
        put(rr, ik, 3.0 * G * l * f.Q_qY * Yk / s);
        put(rr, il, 3.0 * G * Qq / s);
      };
      if (iq >= 0) q_row(row++);
      // driver row (its Jacobian below)
      r[row] = (kd - dEnd.value) / ss;
      ++row;
      // shear consistency
      if (il >= 0) {
        if (apex_) {
          q_row(row++);
        } else {
          r[row] = (f.F / Y - 1.0 - inverse_.value(l)) * Y / s;
          put(row, 0, f.F_p / s);
          put(row, iq, f.F_q / s);
          put(row, ik, (f.F_Y - (1.0 + inverse_.value(l))) * Yk / s);
          put(row, il, -inverse_.derivative(l) * Y / s);
          ++row;
        }
      }
      if (it >= 0) {
        const TensionCutoff& cut = model_.tension_cutoff();
        r[row] = (-p - cut.limit - Y * inverse_.value(lt)) / s;
        put(row, 0, -1.0 / s);
        put(row, ik, -inverse_.value(lt) * Yk / s);
        put(row, it, -inverse_.derivative(lt) * Y / s);
        ++row;
      }
      if (J != nullptr) driver_jacobian(*J, dEnd, f, Yk, ik, iq, il, it);
      return r;
    }

    // The driver row's Jacobian by its chain rule: kd_end(l, Q_p(p, q, Y), Q_q(p, q, Y), lt).
    template <class DriverEnd>
    void driver_jacobian(Matrix& J, const DriverEnd& d, const PQForm& f, double Yk, int ik, int iq, int il,
                         int it) const {
      const int row = 1 + (iq >= 0 ? 1 : 0);
      const double ss = state_scale_;
      const double on = shear_ ? 1.0 : 0.0;
      J(row, 0) = -(d.d_Qp * f.Q_pp + d.d_Qq * f.Q_pq) * on / ss;
      if (iq >= 0) J(row, iq) = -(d.d_Qp * f.Q_pq + d.d_Qq * f.Q_qq) * on / ss;
      J(row, ik) = (1.0 - (d.d_Qp * f.Q_pY + d.d_Qq * f.Q_qY) * Yk * on) / ss;
      if (il >= 0) J(row, il) = -d.d_dl / ss;
      if (it >= 0) J(row, it) = -d.d_dlt / ss;
    }

    const Model& model_;
    OverstressInverse inverse_;
    Sym6 sigma_tr_;
    double k0_[kStates];
    double p_tr_ = 0.0, q_tr_ = 0.0, scale_ = 1.0, state_scale_ = 1.0;
    double K_ = 0.0, G_ = 0.0;  // constant moduli (0: pressure-dependent)
    bool has_q_ = false, apex_ = false, allow_apex_ = true, shear_ = false, tension_ = false;
    double p_ = 0.0, q_ = 0.0, kd_ = 0.0;
  };

  // The return of a Lode-dependent surface with its exact Jacobian (method-notes eqs.
  // (2.5.11)–(2.5.16)): the deviator sqrt(2/3) (q_a e1 + q_b e2) in the coaxial plane of
  // eq. (2.5.3), q_a = q cos b and q_b = q sin b, of Lode angle theta_tr - b; F and the flow from
  // the surface's (p', q, theta) form. Unknowns p', q_a and q_b (unless the trial is hydrostatic
  // or the deviator is held at the apex; q_b off the triaxial corners only), the driver of Y and
  // the active multipliers; rows those of the generic problem (the p' equation, the deviator's
  // on e1 and e2, the driver, the consistency conditions; at the apex the row on e1 replaces
  // the shear one). Cartesian q_a, q_b rather than (q, b): the rows stay nearly linear (exactly,
  // on a Mohr–Coulomb face), and Newton converges from trials far outside as the generic one does.
  class LodeProblem {
   public:
    LodeProblem(const Model& model, const Sym6& sigma_tr, const double* k0, double tau)
        : model_(model), inverse_{model.overstress(), model.fluidity() * tau} {
      for (int j = 0; j < kStates; ++j) k0_[j] = k0[j];
      const double mean_tr = tensor::trace(sigma_tr) / 3.0;
      const Sym6 s = tensor::deviator(sigma_tr);
      const double ns = std::sqrt(tensor::ddot(s, s));
      p_tr_ = -mean_tr;
      scale_ = std::max({model.hardening().size(k0), ns, std::abs(mean_tr)});
      inv_scale_ = 1.0 / scale_;
      q_apex_ = kRoot32 * kApexOffset * scale_;
      plane_ = CoaxialPlane::of(s, 1e-13 * scale_);
      has_q_ = plane_.has_e1;
      has_b_ = plane_.has_e2;
      if (has_q_) q_tr_ = kRoot32 * ns;
      const double c30 = std::sqrt(3.0) / 2.0, c = plane_.cos_theta, sn = plane_.sin_theta;
      corners_[0] = {c * c30 + sn * 0.5, sn * c30 - c * 0.5};  // b = theta_tr - pi/6
      corners_[1] = {c * c30 - sn * 0.5, sn * c30 + c * 0.5};  // b = theta_tr + pi/6
      p_ = p_tr_;
      qa_ = q_tr_;
      kd_ = k0_[Hardening::kDriver];
      const PressureDependentModuli& pm = model.pressure_moduli();
      if (!pm.active()) {
        K_ = model.elastic().K;
        G_ = model.elastic().G;
      }
    }

    double dl = 0.0, dl_t = 0.0;

    /// The trial's overstress F/Y - 1 from the form (the surface's value() in invariants).
    double trial_overstress() {
      trial_form_ = model_.surface().pq_theta(p_tr_, q_tr_, plane_.lode_angle(1.0, 0.0).lode, size());
      has_trial_form_ = true;
      return trial_form_.F / size() - 1.0;
    }
    /// A hydrostatic trial whose potential has no volumetric part: no shear flow (eq. (2.5.5)).
    bool shear_inert() const {
      if (has_q_) return false;
      const double Qp = model_.surface().pq_theta(p_, 0.0, LodeAngle{}, size()).Q_p;
      return std::abs(Qp) <= 1e-12 * (1.0 + std::abs(Qp) / std::sqrt(3.0));  // |tr m| against |m|
    }
    bool at_apex() const { return apex_; }
    bool apex_inside() const {
      const double Y = size();
      return model_.surface().pq_theta(p_, 0.0, LodeAngle{}, Y).F / Y - 1.0 < inverse_.value(dl) - 1e-9;
    }
    void forbid_apex() {
      allow_apex_ = false;
      apex_ = false;
      p_ = p_tr_;
      qa_ = q_tr_;
      qb_ = 0.0;
      kd_ = k0_[Hardening::kDriver];
      dl = dl_t = 0.0;
    }
    double size() const { return model_.hardening().size_of(kd_); }
    Sym6 sigma() const {
      Sym6 s{};
      const double a = kRoot23 * qa_, b = kRoot23 * qb_;
      for (std::size_t i = 0; i < 6; ++i) s[i] = a * plane_.e1[i] + b * plane_.e2[i];
      for (std::size_t i = 0; i < 3; ++i) s[i] -= p_;
      return s;
    }

    ImplicitOutcome newton(bool shear, bool tension) {
      shear_ = shear;
      tension_ = tension;
      apex_ = false;
      if (!shear_) dl = 0.0;
      if (!tension_) dl_t = 0.0;
      if (shear_ && dl <= 0.0) {
        // A linearised guess (eq. 2.5.5), dF/dsigma : D^e : m in these coordinates, and the
        // driver it gives.
        const double Y = size();
        const Polar at = polar(qa_, qb_);
        // At the trial (the first pass) the form is that of trial_overstress().
        const bool at_trial =
            has_trial_form_ && p_ == p_tr_ && qa_ == q_tr_ && qb_ == 0.0 && kd_ == k0_[Hardening::kDriver];
        const LodeForm f = at_trial ? trial_form_ : model_.surface().pq_theta(p_, at.q, at.angle.lode, Y);
        const Flow m = flow(p_, at.q, at.angle, Y, &f);
        const double F_b_over_q = at.q > 0.0 ? -at.angle.sign * f.F_theta / at.q : 0.0;
        const double stiff = std::abs(f.F_p * K() * m.Qp + 3.0 * G() * (f.F_q * m.Qq + F_b_over_q * m.V)) / Y;
        const double soft = std::isinf(inverse_.gamma_tau) ? 0.0 : 1.0 / inverse_.gamma_tau;
        dl = std::max(0.0, f.F / Y - 1.0 - model_.overstress().dead_band) / std::max(stiff + soft, 1e-300);
        kd_ = model_.hardening().driver_end(k0_[Hardening::kDriver], dl, m.Qp, m.Qd, dl_t).value;
      }
      state_scale_ = std::max({std::abs(k0_[Hardening::kDriver]), std::abs(kd_), Hardening::kDriverScale});
      inv_state_scale_ = 1.0 / state_scale_;
      ImplicitOutcome out;
      int corner_stops = 0;
      Vector z = unknowns();
      Point here, there;  // the rows' ingredients at z and at the line search's trial point
      Point* at = &here;
      Point* at_new = &there;
      Matrix J;
      Vector r = evaluate(z, *at);
      for (int it = 0; it < kMaxIterations; ++it) {
        if (r.norm_inf() <= kTolerance) {
          end_Qp_ = at->m.Qp;
          end_Qd_ = at->m.Qd;
          out.converged = true;
          return out;
        }
        ++out.iterations;
        jacobian(*at, J);
        Vector dz, rr = r;
        const double merit = r.squared_norm();
        const bool solved = solve_small(J, rr, dz);
        // Newton drives the deviator through the axis (q_a < 0), or it already sits clamped there.
        const bool at_axis = q_free() && shear_ && allow_apex_ && (z[1] == 0.0 || (solved && z[1] + dz[1] < 0.0));
        if (!solved && !at_axis) return out;
        // A step that carries the Lode angle through a triaxial corner ends there (eq. (2.5.16)):
        // the flow's part normal to s vanishes at the corner and turns within its rounding, so
        // Newton from a face would jump to the other face and back.
        if (solved && !at_axis && b_free() && shear_ && corner_stops < kMaxCornerStops &&
            model_.surface().sharp_corners()) {
          const double to_corner = corner_crossing(z, dz);
          if (to_corner < 1.0) {
            ++corner_stops;
            for (int i = 0; i < z.size(); ++i) z[i] += to_corner * dz[i];
            set(z);
            r = evaluate(z, *at);
            continue;
          }
        }
        double alpha = 1.0;
        Vector z_new = z;
        Vector r_new;
        bool decreased = false;
        for (int ls = 0; ls < 12 && solved && !decreased; ++ls) {
          for (int i = 0; i < z.size(); ++i) z_new[i] = z[i] + alpha * dz[i];
          if (q_free() && z_new[1] < 0.0) {  // q_a >= 0: a flip through the axis is not a return
            z_new[1] = 0.0;
            if (has_b_) z_new[2] = 0.0;
          }
          r_new = evaluate(z_new, *at_new);
          const double m = r_new.squared_norm();
          decreased = std::isfinite(m) && m < (1.0 - 1e-4 * alpha) * merit;
          if (!decreased) alpha *= 0.5;
        }
        if (!decreased && at_axis) {
          // Newton drives the deviator through zero and no shorter step helps: the apex
          // (eq. 2.5.5), the flow's limit along the trial's deviator.
          apex_ = true;
          qa_ = qb_ = 0.0;
          z = unknowns();
          r = evaluate(z, *at);
          continue;
        }
        if (!decreased) {
          out.converged = r.norm_inf() <= kRoundOffTolerance;
          end_Qp_ = at->m.Qp;
          end_Qd_ = at->m.Qd;
          return out;
        }
        z = z_new;
        r = r_new;
        std::swap(at, at_new);
        set(z);
      }
      out.converged = r.norm_inf() <= kTolerance;
      end_Qp_ = at->m.Qp;
      end_Qd_ = at->m.Qd;
      return out;
    }

    void finish(Sym6& sigma_out, double* k) const {
      sigma_out = sigma();
      // The full history from the plastic strain dl m + dl_t/3 1 (eq. 2.5.1): its deviatoric
      // equivalent is dl sqrt(Q_q^2 + V^2), its volume -dl Q_p + dl_t (eq. (2.5.14)).
      model_.hardening().pq_states(k0_, shear_ ? dl : 0.0, end_Qp_, end_Qd_, tension_ ? dl_t : 0.0, k);
      k[Hardening::kDriver] = kd_;
    }

   private:
    static constexpr int kMaxCornerStops = 2;  // a Newton solve's stops at the corners

    double K() const { return K_ > 0.0 ? K_ : model_.pressure_moduli().bulk_modulus(p_); }
    double G() const { return G_ > 0.0 ? G_ : model_.pressure_moduli().shear_modulus(K()); }

    bool q_free() const { return has_q_ && !apex_; }
    bool b_free() const { return q_free() && has_b_; }
    int count() const { return 2 + (q_free() ? 1 : 0) + (b_free() ? 1 : 0) + (shear_ ? 1 : 0) + (tension_ ? 1 : 0); }
    Vector unknowns() const {
      Vector z(count());
      int i = 0;
      z[i++] = p_;
      if (q_free()) z[i++] = qa_;
      if (b_free()) z[i++] = qb_;
      z[i++] = kd_;
      if (shear_) z[i++] = dl;
      if (tension_) z[i++] = dl_t;
      return z;
    }
    void set(const Vector& z) {
      int i = 0;
      p_ = z[i++];
      if (q_free()) qa_ = z[i++];
      if (b_free()) qb_ = z[i++];
      kd_ = z[i++];
      if (shear_) dl = z[i++];
      if (tension_) dl_t = z[i++];
    }

    // The fraction of the step dz at which the deviator crosses a triaxial corner's ray in the
    // plane (theta_tr - b = +-pi/6), or 1 (eq. (2.5.16)).
    double corner_crossing(const Vector& z, const Vector& dz) const {
      double fraction = 1.0;
      for (const Ray& c : corners_) {
        const double side0 = z[1] * c.sin - z[2] * c.cos;
        const double side1 = (z[1] + dz[1]) * c.sin - (z[2] + dz[2]) * c.cos;
        if (!(side0 * side1 < 0.0)) continue;
        const double t = side0 / (side0 - side1);
        // On the ray itself, not its opposite; from a start at the corner, no stop.
        if (t > 1e-6 && (z[1] + t * dz[1]) * c.cos + (z[2] + t * dz[2]) * c.sin > 0.0) fraction = std::min(fraction, t);
      }
      return fraction;
    }

    // q, cos b, sin b and the Lode angle theta_tr - b of the deviator (q_a, q_b) (eq. (2.5.11)).
    struct Polar {
      double q, cb, sb;
      FoldedLodeAngle angle;
    };
    Polar polar(double qa, double qb) const {
      const double q = std::sqrt(qa * qa + qb * qb);
      if (!(q > 0.0)) return {0.0, 1.0, 0.0, plane_.lode_angle(1.0, 0.0)};
      const double inv = 1.0 / q;
      const double cb = qa * inv, sb = qb * inv;
      return {q, cb, sb, plane_.lode_angle(cb, sb)};
    }

    // The flow's components at (p', q, b) and their derivatives (eq. (2.5.13)), along p', q, b
    // and Y: Q_p, Q_q, V = Q_b/q (the part normal to s per unit q; Q_b = -dQ/dtheta) and
    // Q_d = sqrt(Q_q^2 + V^2) (the equivalent strain per unit dl). Zero where the mechanism
    // does not act; no deviatoric part for a hydrostatic trial. The flow is taken at q, at the
    // apex offset at least (as the generic problem's, eq. (2.5.5)); f is the form at q.
    struct Flow {
      double Qp = 0.0, Qp_p = 0.0, Qp_q = 0.0, Qp_b = 0.0, Qp_Y = 0.0;
      double Qq = 0.0, Qq_p = 0.0, Qq_q = 0.0, Qq_b = 0.0, Qq_Y = 0.0;
      double V = 0.0, V_p = 0.0, V_q = 0.0, V_b = 0.0, V_Y = 0.0;
      double Qd = 0.0, Qd_p = 0.0, Qd_q = 0.0, Qd_b = 0.0, Qd_Y = 0.0;
    };
    Flow flow(double p, double q, const FoldedLodeAngle& angle, double Y, const LodeForm* f = nullptr) const {
      Flow m;
      if (!shear_) return m;
      const double qf = has_q_ ? std::max(q, q_apex_) : 0.0;
      const bool along_q = has_q_ && q > q_apex_;  // the flow varies with q
      LodeForm at_qf;
      const LodeForm* form = f;
      if (form == nullptr || qf != q) {
        at_qf = model_.surface().pq_theta(p, qf, angle.lode, Y);
        form = &at_qf;
      }
      const LodeForm& g = *form;
      const double to_b = -angle.sign;  // dtheta/db through the fold
      m.Qp = g.Q_p;
      m.Qp_p = g.Q_pp;
      m.Qp_q = along_q ? g.Q_pq : 0.0;
      m.Qp_b = to_b * g.Q_ptheta;
      m.Qp_Y = g.Q_pY;
      if (!has_q_) return m;
      const double inv_q = 1.0 / qf;
      m.Qq = g.Q_q;
      m.Qq_p = g.Q_pq;
      m.Qq_q = along_q ? g.Q_qq : 0.0;
      m.Qq_b = to_b * g.Q_qtheta;
      m.Qq_Y = g.Q_qY;
      m.V = to_b * g.Q_theta * inv_q;
      m.V_p = to_b * g.Q_ptheta * inv_q;
      m.V_q = along_q ? (to_b * g.Q_qtheta - m.V) * inv_q : 0.0;
      m.V_b = g.Q_thetatheta * inv_q;
      m.V_Y = to_b * g.Q_thetaY * inv_q;
      m.Qd = std::sqrt(m.Qq * m.Qq + m.V * m.V);
      if (m.Qd > 0.0) {
        const double inv = 1.0 / m.Qd;
        m.Qd_p = (m.Qq * m.Qq_p + m.V * m.V_p) * inv;
        m.Qd_q = (m.Qq * m.Qq_q + m.V * m.V_q) * inv;
        m.Qd_b = (m.Qq * m.Qq_b + m.V * m.V_b) * inv;
        m.Qd_Y = (m.Qq * m.Qq_Y + m.V * m.V_Y) * inv;
      }
      return m;
    }

    // What the rows are made of at one iterate: the Jacobian is built from it only where Newton
    // steps from that iterate (not at the line search's rejected points, nor at convergence).
    struct Point {
      int n = 0, ia = -1, ib = -1, ik = 0, il = -1, it = -1;
      double l = 0.0, lt = 0.0, cb = 1.0, sb = 0.0, inv_q = 0.0, Y = 0.0, Yk = 0.0;
      double G = 0.0, dG_dp = 0.0, dp_dev = 0.0, x = 0.0, x_t = 0.0;
      double F_p = 0.0, F_q = 0.0, F_b = 0.0, F_Y = 0.0;
      double d_Qp = 0.0, d_Qd = 0.0, d_dl = 0.0, d_dlt = 0.0;  // the driver's partials
      Flow m;
    };

    // Residuals: the generic problem's rows, the deviator's in units of |s| (eq. (2.5.15)).
    Vector evaluate(const Vector& z, Point& pt) const {
      int i = 0;
      pt.n = z.size();
      const double p = z[i++];
      pt.ia = q_free() ? i++ : -1;
      pt.ib = b_free() ? i++ : -1;
      pt.ik = i++;
      pt.il = shear_ ? i++ : -1;
      pt.it = tension_ ? i++ : -1;
      const double qa = pt.ia >= 0 ? z[pt.ia] : 0.0;
      const double qb = pt.ib >= 0 ? z[pt.ib] : 0.0;
      const double kd = z[pt.ik];
      const double l = pt.il >= 0 ? z[pt.il] : 0.0;
      const double lt = pt.it >= 0 ? z[pt.it] : 0.0;
      pt.l = l;
      pt.lt = lt;
      const Hardening& hard = model_.hardening();
      const double Y = hard.size_of(kd);
      pt.Y = Y;
      pt.Yk = hard.size_slope(kd);
      const Polar at = polar(qa, qb);
      pt.cb = at.cb;
      pt.sb = at.sb;
      pt.inv_q = 1.0 / (at.q > 0.0 ? at.q : q_apex_);
      const LodeForm f = model_.surface().pq_theta(p, at.q, at.angle.lode, Y);
      pt.m = flow(p, at.q, at.angle, Y, &f);
      const Flow& m = pt.m;
      pt.F_p = f.F_p;
      pt.F_q = f.F_q;
      pt.F_b = -at.angle.sign * f.F_theta;
      pt.F_Y = f.F_Y;
      // The deviatoric flow on e1 and e2 (per sqrt(3/2)): Q_q along s, V normal to it.
      const double ma = m.Qq * at.cb - m.V * at.sb, mb = m.Qq * at.sb + m.V * at.cb;
      const double ev = -l * m.Qp + lt;  // plastic volumetric strain, dilation positive
      // p' after ev: K ev at constant moduli, the exact swelling law with p'-dependent ones.
      const PressureDependentModuli& pm = model_.pressure_moduli();
      double p_end = 0.0;
      if (pm.active()) {
        p_end = pm.pressure_after_plastic_volume(p_tr_, ev);
        pt.dp_dev = pm.v0_over_kappa * std::clamp(p_end, pm.p_min, pm.p_max);
        pt.G = pm.shear_modulus(pm.bulk_modulus(p));
        const bool inside = p > pm.p_min && p < pm.p_max;
        pt.dG_dp = pm.constant_shear || !inside ? 0.0 : pm.G_over_K * pm.v0_over_kappa;
      } else {
        p_end = p_tr_ + K_ * ev;
        pt.dp_dev = K_;
        pt.G = G_;
      }
      const auto dEnd = hard.driver_end(k0_[Hardening::kDriver], l, m.Qp, m.Qd, lt);
      pt.d_Qp = dEnd.d_Qp;
      pt.d_Qd = dEnd.d_Qq;
      pt.d_dl = dEnd.d_dl;
      pt.d_dlt = dEnd.d_dlt;
      const double s = inv_scale_, ds = kRoot23 * inv_scale_;
      const double G3l = 3.0 * pt.G * l;
      Vector r(pt.n);
      int row = 0;
      r[row++] = (p - p_end) * s;
      if (pt.ia >= 0) r[row++] = (qa - q_tr_ + G3l * ma) * ds;
      if (pt.ib >= 0) r[row++] = (qb + G3l * mb) * ds;
      r[row++] = (kd - dEnd.value) * inv_state_scale_;
      if (pt.il >= 0) {
        pt.x = inverse_.value(l);
        // At the apex the row on e1 (q_a = q_b = 0) replaces the consistency.
        r[row++] = apex_ ? (G3l * ma - q_tr_) * ds : (f.F - Y * (1.0 + pt.x)) * s;
      }
      if (pt.it >= 0) {
        pt.x_t = inverse_.value(lt);
        r[row] = (-p - model_.tension_cutoff().limit - Y * pt.x_t) * s;
      }
      return r;
    }

    // The exact Jacobian of evaluate()'s rows (eq. (2.5.15)): the partials along (p', q, b) of
    // the form, taken to (q_a, q_b) by d/dq_a = cos b d/dq - (sin b/q) d/db and
    // d/dq_b = sin b d/dq + (cos b/q) d/db.
    void jacobian(const Point& pt, Matrix& J) const {
      J.clear(pt.n);
      const Flow& m = pt.m;
      const double cb = pt.cb, sb = pt.sb, inv_q = pt.inv_q, l = pt.l, G = pt.G, Yk = pt.Yk;
      const int ia = pt.ia, ib = pt.ib, ik = pt.ik, il = pt.il, it = pt.it;
      auto put = [&J](int row, int c, double v) {
        if (c >= 0) J(row, c) = v;
      };
      auto along_a = [&](double d_q, double d_b) { return cb * d_q - sb * inv_q * d_b; };
      auto along_b = [&](double d_q, double d_b) { return sb * d_q + cb * inv_q * d_b; };
      const double s = inv_scale_, ss = inv_state_scale_, ds = kRoot23 * inv_scale_;
      int row = 0;
      // p' row
      put(row, 0, (1.0 + pt.dp_dev * l * m.Qp_p) * s);
      put(row, ia, pt.dp_dev * l * along_a(m.Qp_q, m.Qp_b) * s);
      put(row, ib, pt.dp_dev * l * along_b(m.Qp_q, m.Qp_b) * s);
      put(row, ik, pt.dp_dev * l * m.Qp_Y * Yk * s);
      put(row, il, pt.dp_dev * m.Qp * s);
      put(row, it, -pt.dp_dev * s);
      ++row;
      // The deviator's rows: m_a = Q_q cos b - V sin b, m_b = Q_q sin b + V cos b.
      const double ma = m.Qq * cb - m.V * sb, mb = m.Qq * sb + m.V * cb;
      const double ma_p = m.Qq_p * cb - m.V_p * sb, mb_p = m.Qq_p * sb + m.V_p * cb;
      const double ma_q = m.Qq_q * cb - m.V_q * sb, mb_q = m.Qq_q * sb + m.V_q * cb;
      const double ma_b = (m.Qq_b - m.V) * cb - (m.Qq + m.V_b) * sb, mb_b = (m.Qq_b - m.V) * sb + (m.Qq + m.V_b) * cb;
      const double ma_Y = m.Qq_Y * cb - m.V_Y * sb, mb_Y = m.Qq_Y * sb + m.V_Y * cb;
      auto row_a = [&](int rr) {
        put(rr, 0, 3.0 * l * (pt.dG_dp * ma + G * ma_p) * ds);
        put(rr, ia, (1.0 + 3.0 * G * l * along_a(ma_q, ma_b)) * ds);
        put(rr, ib, 3.0 * G * l * along_b(ma_q, ma_b) * ds);
        put(rr, ik, 3.0 * G * l * ma_Y * Yk * ds);
        put(rr, il, 3.0 * G * ma * ds);
      };
      if (ia >= 0) row_a(row++);
      if (ib >= 0) {
        put(row, 0, 3.0 * l * (pt.dG_dp * mb + G * mb_p) * ds);
        put(row, ia, 3.0 * G * l * along_a(mb_q, mb_b) * ds);
        put(row, ib, (1.0 + 3.0 * G * l * along_b(mb_q, mb_b)) * ds);
        put(row, ik, 3.0 * G * l * mb_Y * Yk * ds);
        put(row, il, 3.0 * G * mb * ds);
        ++row;
      }
      // driver: kd_end(dl, Q_p, Q_d, dl_t) by the chain rule
      put(row, 0, -(pt.d_Qp * m.Qp_p + pt.d_Qd * m.Qd_p) * ss);
      put(row, ia, -(pt.d_Qp * along_a(m.Qp_q, m.Qp_b) + pt.d_Qd * along_a(m.Qd_q, m.Qd_b)) * ss);
      put(row, ib, -(pt.d_Qp * along_b(m.Qp_q, m.Qp_b) + pt.d_Qd * along_b(m.Qd_q, m.Qd_b)) * ss);
      put(row, ik, (1.0 - (pt.d_Qp * m.Qp_Y + pt.d_Qd * m.Qd_Y) * Yk) * ss);
      put(row, il, -pt.d_dl * ss);
      put(row, it, -pt.d_dlt * ss);
      ++row;
      // shear consistency (at the apex, the row on e1)
      if (il >= 0) {
        if (apex_) {
          row_a(row++);
        } else {
          put(row, 0, pt.F_p * s);
          put(row, ia, along_a(pt.F_q, pt.F_b) * s);
          put(row, ib, along_b(pt.F_q, pt.F_b) * s);
          put(row, ik, (pt.F_Y - (1.0 + pt.x)) * Yk * s);
          put(row, il, -inverse_.derivative(l) * pt.Y * s);
          ++row;
        }
      }
      if (it >= 0) {
        put(row, 0, -s);
        put(row, ik, -pt.x_t * Yk * s);
        put(row, it, -inverse_.derivative(pt.lt) * pt.Y * s);
      }
    }

    const Model& model_;
    OverstressInverse inverse_;
    double k0_[kStates];
    CoaxialPlane plane_;  // eqs. (2.5.3), (2.5.11)
    struct Ray {
      double cos, sin;
    };
    Ray corners_[2]{};  // the directions b of the triaxial corners, theta_tr -+ pi/6
    double p_tr_ = 0.0, q_tr_ = 0.0;
    double scale_ = 1.0, inv_scale_ = 1.0, state_scale_ = 1.0, inv_state_scale_ = 1.0, q_apex_ = 0.0;
    double K_ = 0.0, G_ = 0.0;  // constant moduli (0: pressure-dependent)
    bool has_q_ = false, has_b_ = false, apex_ = false, allow_apex_ = true, shear_ = false, tension_ = false;
    double p_ = 0.0, qa_ = 0.0, qb_ = 0.0, kd_ = 0.0;
    double end_Qp_ = 0.0, end_Qd_ = 0.0;  // the flow at the end of the last Newton solve, for finish()
    LodeForm trial_form_;                 // the form at the trial, from trial_overstress()
    bool has_trial_form_ = false;
  };

  const Model& model_;
  Path path_;
};

}  // namespace rktsph::detail
