#pragma once
// V2's mode-selective hourglass control (method-notes §2.6): after step 2 has advanced the nodes
// by V1's Taylor–Galerkin velocity update, a pair dashpot on the part of the nodal velocity
// difference that the step's own velocity gradient does not explain, and a pair diffusion of the
// part of the nodal mean-stress difference its gradient does not explain:
//   m_IJ = ṽ_I − ṽ_J − ½(L_I + L_J) x_IJ,    a_I = (1/m_I) Σ_J κ_IJ (m_IJ·e) e,              (2.6.2)
//   s_IJ = σ̃_I − σ̃_J − ½(g_I + g_J)·x_IJ,    dσ_m,I/dt = (1/V_I) Σ_J δ_IJ s_IJ,              (2.6.3)
// (σ̃ the mean stress, g its gradient) with κ_IJ = 2 ξ ρ̄ c̄ h V_I V_J W′/r and δ_IJ = 2 ζ c̄ h
// V_I V_J W′/r (both ≤ 0). Both vanish on linear fields whatever the particle arrangement (the
// corrected gradients are exact there), so a smooth flow or a lithostatic stress is not touched,
// while the nodal checkerboards the stress points cannot see (P_EN f = 0) decay. Pair-
// antisymmetric and central: linear and angular momentum are conserved. No state between steps.
#include <array>
#include <vector>

#include "core/execution.hpp"
#include "neighbours/relation.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
class HourglassControl {
 public:
  static constexpr int NS = kStressComponents<Dim>;
  /// ξ of eq. (2.6.2): a lattice checkerboard loses about 0.2 of itself a step at C = 0.8
  /// (method-notes §2.6; the lattice constants 3.47 in 1D, 2.00 in 2D, 1.40 in 3D set the
  /// dimension's value). The elastic plate in bending loses 1.8–2.0 % a period with it.
  static constexpr double kVelocityCoefficient = Dim == 1 ? 0.06 : (Dim == 2 ? 0.1 : 0.15);
  /// The Mach numbers of the velocity mismatch and of the compression h |div v| / c at which a
  /// node takes the simple scheme's velocity (a shock, eq. (2.6.4)).
  static constexpr double kMismatchMach = 0.02;
  static constexpr double kCompressionMach = 0.02;
  /// ζ of eq. (2.6.3), on the mean stress only: a deviatoric diffusion also acts on the
  /// quadratic stress across a thin body's surface rows (the plate lost 14 % a period with it).
  static constexpr double kStressCoefficient = 0.05;

  explicit HourglassControl(StaggeredModel<Dim>& model) : m_(model) {}

  /// Room for every node (grows only).
  void reserve(Index nodes);

  /// Node i's state of the step, from step 2: its position and velocity at t^n, its velocity
  /// after the Taylor–Galerkin update and the simple scheme's, the step's velocity gradient L
  /// (grad_v[d][k] = dv_k/dx_d), its stress σ̃ = R σ^n + ½ Δt σ̇ and the stress gradient
  /// (grad_s[d][c] = dσ_c/dx_d), of which the pass keeps the mean parts. `irregular`: the node is
  /// on the free surface and its row from the stress points was regularised by the gradient floor
  /// or is degenerate (a lone node squeezed out of the surface): its gradients are not exact, the
  /// mode-selective terms are not either, and it takes the simple scheme's velocity (eq. (2.6.4),
  /// w = 1).
  void record(Index i, const Vec<Dim>& x_n, const double* v_n, const double* v_star, const double* v_simple,
              const double (&grad_v)[Dim][Dim], const double* sigma_tilde, const double (&grad_s)[Dim][NS],
              bool irregular) {
    const auto u = static_cast<std::size_t>(i);
    Node& n = nodes_[u];
    n.irregular = irregular;
    for (int d = 0; d < Dim; ++d) {
      n.x[d] = x_n[d];
      n.v[d] = 0.5 * (v_n[d] + v_star[d]);
      n.vs[d] = v_simple[d] - v_star[d];
      for (int k = 0; k < Dim; ++k) n.L[d][k] = grad_v[d][k];
      n.gm[d] = (grad_s[d][0] + grad_s[d][1] + grad_s[d][2]) / 3.0;
    }
    n.mean = (sigma_tilde[0] + sigma_tilde[1] + sigma_tilde[2]) / 3.0;
  }

  /// The pass over the nodes' Verlet neighbours (at the positions of t^n): v += Δt a, the normal
  /// stresses += Δt dσ_m, and the flux rate of the source (rows of NS, when given) likewise, so
  /// that the viscoplastic return sees the diffused trial (method-notes eq. (2.6.1)).
  void apply(double dt, const Relation<Dim>& neighbours, FieldView<double, Dim> velocity, FieldView<double, NS> stress,
             double* flux_rate);

  /// The energy the last pass removed from the nodal kinetic energy (J), and its split into the
  /// pure dissipation of eq. (2.6.5) and the exchange with the resolved field.
  double kinetic_change() const { return kinetic_change_; }
  /// The change of the nodes' stored energy ½ σ:C⁻¹:σ V the stress diffusion made in the last
  /// pass, J.
  double strain_change() const { return strain_change_; }
  double dissipation() const { return dissipation_; }
  double exchange() const { return exchange_; }
  /// Node i's acceleration of the last pass (its velocity part and the limiter's), m/s^2.
  double acceleration(Index i, int d) const {
    return accel_[static_cast<std::size_t>(i) * Dim + static_cast<std::size_t>(d)];
  }
  /// The largest per-step decay factor θ_I = Δt Σ_J |κ_IJ| / m_I of the last pass (eq. (2.6.4)).
  double theta_max() const { return theta_max_; }
  std::size_t bytes() const { return nodes_.capacity() * sizeof(Node) + accel_.capacity() * sizeof(double); }

 private:
  struct Node {
    double x[Dim];
    double v[Dim];
    double L[Dim][Dim];
    double mean;     // σ̃_m
    double gm[Dim];  // its gradient
    double vs[Dim];  // the simple scheme's velocity minus the Taylor–Galerkin one
    bool irregular;  // a surface node, its row regularised or degenerate: the simple scheme's velocity
  };

  StaggeredModel<Dim>& m_;
  std::vector<Node> nodes_;
  std::vector<double> accel_;   // a_I, Dim a node
  std::vector<double> dsigma_;  // dσ_m,I/dt, one a node
  std::vector<double> theta_;   // θ_I of the last pass
  std::vector<double> speed_;   // c_I, the pass's wave speeds
  exec::ReductionScratch reduction_;
  double kinetic_change_ = 0.0, strain_change_ = 0.0, dissipation_ = 0.0, exchange_ = 0.0, theta_max_ = 0.0;
};

}  // namespace rktsph
