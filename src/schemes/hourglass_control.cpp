// V2's hourglass control (schemes/hourglass_control.hpp, method-notes §2.6).
#include "schemes/hourglass_control.hpp"

#include <algorithm>
#include <cmath>

#include "materials/tensor.hpp"

namespace rktsph {

template <int Dim>
void HourglassControl<Dim>::reserve(Index nodes) {
  const auto n = static_cast<std::size_t>(nodes);
  if (nodes_.size() < n) {
    nodes_.resize(n);
    accel_.resize(n * Dim);
    dsigma_.resize(n);
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
        double f[Dim] = {}, ds = 0.0;
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
            // The mean-stress mismatch (eq. (2.6.3)).
            double gx = 0.0;
            for (int d = 0; d < Dim; ++d) gx += (a.gm[d] + b.gm[d]) * x[d];
            ds += 2.0 * zeta * c_bar * h * vv * dw_over_r * (a.mean - b.mean - 0.5 * gx);
          }
        }
        double power = 0.0;
        // Where the velocity departs from its linear prediction at a Mach number |m.e| / c beyond
        // kMismatchMach, or the node is compressed at a Mach number h |div v| / c beyond
        // kCompressionMach (a shock: 0.2 in Case 7's front, 1e-3 in Case 9's collapse), the
        // first-order simple scheme's velocity (eq. (2.6.4)).
        double divergence = 0.0;
        for (int d = 0; d < Dim; ++d) divergence += a.L[d][d];
        const double compression = -h * divergence / c_i;
        // Below a tenth of the threshold, nothing: the round-off of a linear field stays exact.
        // A surface node whose row is regularised or degenerate, wholly (as the weighted simple
        // scheme of eq. (2.3.2) did there): V1's step 2 lets such lone nodes run away.
        const double w = a.irregular ? 1.0
                                     : std::max(std::clamp((mismatch / kMismatchMach - 0.1) / 0.9, 0.0, 1.0),
                                                std::clamp(compression / kCompressionMach - 1.0, 0.0, 1.0));
        for (int d = 0; d < Dim; ++d) {
          const double ad = (V_i > 0.0 ? f[d] / mass_i : 0.0) + (dt > 0.0 ? w * a.vs[d] / dt : 0.0);
          accel[iu * Dim + static_cast<std::size_t>(d)] = ad;
          power += f[d] * a.v[d];
        }
        dsigma[iu] = V_i > 0.0 ? ds / V_i : 0.0;
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
  // Apply, and the stored energy's change: V [σ* : C⁻¹ : Δσ + ½ Δσ : C⁻¹ : Δσ], Δσ = Δt dσ/dt.
  const std::array<double, 1> strain = exec::particle_reduce<1>(
      m_.policy, n, reduction_, [&](Index i, double* acc) {
        const auto iu = static_cast<std::size_t>(i);
        for (int d = 0; d < Dim; ++d) velocity(i, d) += dt * accel[iu * Dim + static_cast<std::size_t>(d)];
        Sym6 before{}, change{};
        const double ds = dsigma[iu];
        for (int c = 0; c < NS; ++c) before[static_cast<std::size_t>(c)] = stress(i, c);
        for (int c = 0; c < 3; ++c) {
          change[static_cast<std::size_t>(c)] = dt * ds;
          stress(i, c) += dt * ds;
          if (flux_rate != nullptr) flux_rate[iu * NS + static_cast<std::size_t>(c)] += ds;
        }
        const Sym6 e = m_.materials[static_cast<std::size_t>(set.material[iu])].elastic().apply_inverse(change);
        for (std::size_t c = 0; c < 6; ++c) before[c] += 0.5 * change[c];
        acc[0] += set.volume[iu] * tensor::ddot(before, e);
      });
  strain_change_ = strain[0];
  exchange_ = sums[0] - sums[1];
  dissipation_ = sums[1];
  theta_max_ = n > 0 ? *std::max_element(theta.begin(), theta.begin() + n) : 0.0;
  kinetic_change_ = sums[3];
}

template class HourglassControl<1>;
template class HourglassControl<2>;
template class HourglassControl<3>;

}  // namespace rktsph
