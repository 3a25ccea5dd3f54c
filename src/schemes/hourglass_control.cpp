// V2's hourglass control (schemes/hourglass_control.hpp, method-notes §2.6).
#include "schemes/hourglass_control.hpp"

#include <algorithm>
#include <cmath>

namespace rktsph {

template <int Dim>
void HourglassControl<Dim>::reserve(Index nodes) {
  const auto n = static_cast<std::size_t>(nodes);
  if (nodes_.size() < n) {
    nodes_.resize(n);
    accel_.resize(n * Dim);
    dsigma_.resize(n * NS);
    theta_.resize(n);
    speed_.resize(n);
  }
}

template <int Dim>
void HourglassControl<Dim>::apply(double dt, const Relation<Dim>& neighbours, FieldView<double, Dim> velocity,
                                  FieldView<double, NS> stress, double* flux_rate) {
  const ParticleSet<Dim>& set = m_.nodes;
  const auto n = static_cast<Index>(set.size());
  const double h = m_.kernel.h();
  const double r2max = 4.0 * h * h;
  const double xi = kVelocityCoefficient, zeta = kStressCoefficient;
  const std::vector<double>& modulus = m_.materials.p_modulus;
  std::vector<double>& accel = accel_;
  std::vector<double>& dsigma = dsigma_;
  // Each node's wave speed at its density (eq. (4.3.3)), once.
  std::vector<double>& speed = speed_;
  exec::particle_for(
      m_.policy, n,
      [&](Index i) {
        const auto iu = static_cast<std::size_t>(i);
        speed[iu] = std::sqrt(modulus[static_cast<std::size_t>(set.material[iu])] / set.density[iu]);
      },
      exec::Schedule::even, n);
  const double inv_h = m_.kernel.inv_h(), alpha = m_.kernel.alpha();
  // Per node: the pair sums (eqs. (2.6.2)–(2.6.3)), gathered from the node's own row, so that
  // every pair is evaluated from both sides with the same operands (antisymmetric bit for bit).
  std::vector<double>& theta = theta_;
  const std::array<double, 4> sums = exec::particle_reduce<4>(
      m_.policy, n, reduction_, [&](Index i, double* acc) {
        const auto iu = static_cast<std::size_t>(i);
        const Node& a = nodes_[iu];
        const double rho_i = set.density[iu], V_i = set.volume[iu];
        const double mass_i = rho_i * V_i;
        const double c_i = speed[iu];
        double f[Dim] = {}, ds[NS] = {};
        double kappa_sum = 0.0, dissipation = 0.0, mismatch = 0.0;
        if (V_i > 0.0) {
          for (const Index j : neighbours.row(i)) {
            const auto ju = static_cast<std::size_t>(j);
            const Node& b = nodes_[ju];
            double x[Dim], r2 = 0.0;
            for (int d = 0; d < Dim; ++d) {
              x[d] = a.x[d] - b.x[d];
              r2 += x[d] * x[d];
            }
            // The row holds the node itself and the Verlet skin's pairs; frozen nodes have no volume.
            if (!(r2 < r2max) || r2 == 0.0 || !(set.volume[ju] > 0.0)) continue;
            const double r = std::sqrt(r2);
            const double dw_over_r = CubicSplineKernel<Dim>::scaled_derivative(r, inv_h, alpha) * inv_h;  // <= 0
            const double rho_j = set.density[ju];
            const double c_bar = 0.5 * (c_i + speed[ju]);
            const double vv = V_i * set.volume[ju];
            // The velocity mismatch along the pair (eq. (2.6.2)).
            double me = 0.0;
            for (int k = 0; k < Dim; ++k) {
              double lx = 0.0;
              for (int d = 0; d < Dim; ++d) lx += (a.L[d][k] + b.L[d][k]) * x[d];
              me += (a.v[k] - b.v[k] - 0.5 * lx) * x[k];
            }
            me /= r;
            mismatch = std::max(mismatch, std::abs(me) / c_bar);
            const double kappa = 2.0 * xi * (0.5 * (rho_i + rho_j)) * c_bar * h * vv * dw_over_r;
            const double force = kappa * me / r;
            for (int d = 0; d < Dim; ++d) f[d] += force * x[d];
            kappa_sum -= kappa;
            dissipation += kappa * me * me;
            // The stress mismatch (eq. (2.6.3)): its mean part in full, its deviator as far as
            // neither node is at yield.
            double sm[NS];
            for (int c = 0; c < NS; ++c) {
              double gx = 0.0;
              for (int d = 0; d < Dim; ++d) gx += (a.G[d][c] + b.G[d][c]) * x[d];
              sm[c] = a.s[c] - b.s[c] - 0.5 * gx;
            }
            const double mean = (sm[0] + sm[1] + sm[2]) / 3.0;
            const double keep = 1.0 - std::max(a.yield, b.yield);
            const double delta = 2.0 * zeta * c_bar * h * vv * dw_over_r;
            for (int c = 0; c < 3; ++c) ds[c] += delta * (mean + keep * (sm[c] - mean));
            for (int c = 3; c < NS; ++c) ds[c] += delta * keep * sm[c];
          }
        }
        double power = 0.0;
        // Where the velocity departs from its linear prediction at a Mach number beyond
        // kLimiterMach (a shock), the first-order simple scheme's velocity (eq. (2.6.4)).
        const double w = std::min(1.0, mismatch / kLimiterMach);
        for (int d = 0; d < Dim; ++d) {
          const double ad = (V_i > 0.0 ? f[d] / mass_i : 0.0) + (dt > 0.0 ? w * a.vs[d] / dt : 0.0);
          accel[iu * Dim + static_cast<std::size_t>(d)] = ad;
          power += f[d] * a.v[d];
        }
        for (int c = 0; c < NS; ++c) dsigma[iu * NS + static_cast<std::size_t>(c)] = V_i > 0.0 ? ds[c] / V_i : 0.0;
        acc[0] += power;
        acc[1] += 0.5 * dissipation;  // each pair is summed from both of its nodes
        theta[iu] = V_i > 0.0 ? dt * kappa_sum / mass_i : 0.0;
        // The kinetic energy the velocity update below changes: m a dt (v* + a dt / 2).
        double dk = 0.0;
        for (int d = 0; d < Dim; ++d) {
          const double ad = accel[iu * Dim + static_cast<std::size_t>(d)];
          dk += mass_i * dt * ad * (velocity(i, d) + 0.5 * dt * ad);
        }
        acc[3] += dk;
      });
  exec::particle_for(
      m_.policy, n,
      [&](Index i) {
        const auto iu = static_cast<std::size_t>(i);
        for (int d = 0; d < Dim; ++d) velocity(i, d) += dt * accel[iu * Dim + static_cast<std::size_t>(d)];
        for (int c = 0; c < NS; ++c) {
          const double ds = dsigma[iu * NS + static_cast<std::size_t>(c)];
          stress(i, c) += dt * ds;
          if (flux_rate != nullptr) flux_rate[iu * NS + static_cast<std::size_t>(c)] += ds;
        }
      },
      exec::Schedule::even, n);
  exchange_ = sums[0] - sums[1];
  dissipation_ = sums[1];
  theta_max_ = n > 0 ? *std::max_element(theta.begin(), theta.begin() + n) : 0.0;
  kinetic_change_ = sums[3];
}

template class HourglassControl<1>;
template class HourglassControl<2>;
template class HourglassControl<3>;

}  // namespace rktsph
