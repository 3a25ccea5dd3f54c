// V3: the saturated v-p_w extension of the staggered RKT-SPH solver (METHOD.md §1.4, §2.4,
// §5.3). The explicit part (elements, then v* and sigma' at the nodes) is V1's, with grad p^n
// added to the element half-step (staggered_solver.cpp, marked "V3"); this file holds the
// set-up of the pressure equation and the pressure step: div v*, the PCG solve of
// K p^{n+1} = RHS (solvers/pore_pressure.hpp) and the velocity correction
// v^{n+1} = v* - (dt/rho) grad p^{n+1}.
#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "operators/laplacian.hpp"
#include "solvers/staggered_solver.hpp"

namespace rktsph {

namespace {
// Below this many nodes a loop runs on one thread (as in staggered_solver.cpp): the fork/join
// costs more than it saves.
constexpr Index kParallelMinV3 = 2048;
}  // namespace

template <int Dim>
void StaggeredSolver<Dim>::build_saturated() {
  saturated_ = true;
  const FluidSpec& fl = setup_.fluid;
  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  pw_.assign(nn, fl.initial_pore_pressure);
  pw_old_.assign(nn, 0.0);
  pw_source_.assign(nn, 0.0);
  pw_drained_.assign(nn, false);
  pw_value_.assign(nn, 0.0);
  pw_function_.assign(nn, -1);

  // Pore-pressure conditions (METHOD.md §4.1): drained entries are Dirichlet rows, impermeable
  // entries (and every face not drained) are walls dp/dn = 0. A later entry wins.
  const double tol = 1e-6 * setup_.dx + 1e-12;
  for (const auto& spec : setup_.boundaries) {
    if (!spec.pore_pressure && !spec.impermeable) continue;
    for (std::size_t i = 0; i < nn; ++i) {
      if (!spec.region.contains(disc_.nodes.position[i], tol)) continue;
      pw_drained_[i] = spec.pore_pressure.has_value();
      pw_value_[i] = spec.pore_pressure.value_or(0.0);
      pw_function_[i] = spec.function;
    }
  }
  for (std::size_t i = 0; i < nn; ++i) {
    if (pw_drained_[i]) pw_[i] = pw_value_[i] * setup_.function_value(pw_function_[i], 0.0);
  }

  // Impermeable walls (METHOD.md §4.1, mirror nodes): every face plane of the body that holds
  // a non-drained boundary node. A node uses a plane when the boundary node nearest to its
  // projection on that plane is an impermeable node of that face (so a footing on a drained
  // surface mirrors only under the footing).
  std::vector<MirrorPlane> planes;
  const double eps = 1e-6 * setup_.dx;
  for (std::size_t i = 0; i < nn; ++i) {
    const std::uint8_t faces = disc_.boundary.faces[i];
    for (int bit = 0; bit < 2 * Dim; ++bit) {
      if (((faces >> bit) & 1u) == 0 || pw_drained_[i]) continue;
      const MirrorPlane m{bit / 2, disc_.nodes.position[i][bit / 2], bit % 2 == 0 ? -1 : 1};
      const bool known = std::any_of(planes.begin(), planes.end(), [&](const MirrorPlane& q) {
        return q.axis == m.axis && q.outward == m.outward && std::abs(q.coord - m.coord) < eps;
      });
      if (!known) planes.push_back(m);
    }
  }
  if (planes.size() > 8) {
    throw InputError(fmt::format("{}: the pore-pressure walls lie on {} planes; at most 8 are supported", setup_.file,
                                 planes.size()));
  }
  std::vector<std::uint8_t> mask(nn, 0);
  const double reach = kernel_.support_radius();
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const MirrorPlane& m = planes[k];
    const int bit = 2 * m.axis + (m.outward > 0 ? 1 : 0);
    for (std::size_t i = 0; i < nn; ++i) {
      const Vec<Dim>& x = disc_.nodes.position[i];
      if (std::abs(x[m.axis] - m.coord) >= reach) continue;
      Vec<Dim> foot = x;
      foot[m.axis] = m.coord;
      std::size_t best = nn;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < nn; ++j) {
        if (((disc_.boundary.faces[j] >> bit) & 1u) == 0 || std::abs(disc_.nodes.position[j][m.axis] - m.coord) > eps) continue;
        const double d = (disc_.nodes.position[j] - foot).norm();
        if (d < best_d) {
          best_d = d;
          best = j;
        }
      }
      if (best < nn && best_d < 0.5 * setup_.dx + eps && !pw_drained_[best]) mask[i] = static_cast<std::uint8_t>(mask[i] | (1u << k));
    }
  }

  // The undrained Courant number and the faces where it limits stability (see the header).
  {
    const double q = 1.0 / fl.inverse_storage();
    double ratio = 1.0;
    for (std::size_t m = 0; m < lambda_.size(); ++m) {
      const double drained = lambda_[m] + 2.0 * shear_[m];
      ratio = std::max(ratio, std::sqrt((drained + q) / drained));
    }
    undrained_courant_ = cfl_ * ratio;
    impermeable_stress_faces_ = 0;
    for (const Index i : boundary_nodes_) {
      const auto iu = static_cast<std::size_t>(i);
      if (pw_drained_[iu]) continue;
      bool exposed = false;
      for (int d = 0; d < Dim; ++d) {
        if ((disc_.boundary.faces[iu] >> (2 * d) & 3u) == 0) continue;  // not on a face normal to d
        bool held = false;
        for (Index k = constraint_row_[iu]; k < constraint_row_[iu + 1]; ++k) {
          held = held || constraints_[static_cast<std::size_t>(k)].component == d;
        }
        exposed = exposed || !held;
      }
      if (exposed) ++impermeable_stress_faces_;
    }
  }

  op_nn_ = build_corrected_operator<Dim>(disc_.nodes.position, disc_.nodes, kernel_);
  const NodeLaplacian<Dim> lap = build_node_laplacian<Dim>(disc_.nodes, kernel_, {}, planes, mask);

  // K = I/(Q* dt) - k_eff S with k_eff = k_w + S_w dt/rho (METHOD.md §2.4). One mixture density
  // is assumed for the fractional-step term (the densest material: the largest stabilisation is
  // not needed, the smallest k_eff changes little; a single K keeps it symmetric).
  double rho = 0.0;
  for (const auto& m : materials_) rho = std::max(rho, m->density());
  inv_storage_ = fl.inverse_storage();
  PorePressureSolver::Settings s;
  s.inv_q_dt = inv_storage_ / dt_;
  // The stabilisation time is dt with div v* at the nodes (METHOD.md §2.4) and dt/2 with the
  // stress points' half-step velocity, which carries (dt/2) grad p / rho in a quasi-static state
  // (see pressure_step).
  stabilisation_time_ = fl.divergence_from_stress_points ? 0.5 * dt_ : dt_;
  if (fl.divergence_from_stress_points) elem_v_skeleton_.assign(static_cast<std::size_t>(disc_.elements.size()) * Dim, 0.0);
  s.k_eff = fl.permeability() + fl.saturation * stabilisation_time_ / rho;
  s.tolerance = fl.tolerance;
  s.max_iterations = fl.max_iterations;
  s.preconditioner = fl.incomplete_cholesky ? PressurePreconditioner::incomplete_cholesky
                                            : PressurePreconditioner::diagonal;
  s.deferred_correction = fl.deferred_correction;
  if (fl.incremental) {
    s.incremental = fl.saturation * stabilisation_time_ / rho;
    pw_grad_.assign(nn * static_cast<std::size_t>(Dim), 0.0);
  }
  if (fl.filter > 0.0) {
    // Linear-exact pressure filter (solver.pressure_filter, operators/laplacian.hpp): tau (S_f p -
    // T G p) on the plain node set (no wall mirrors: psi_IJ pairs real nodes), G the corrected
    // node gradient of the velocity correction. It damps odd-even pressure modes, which the
    // incremental projection leaves undamped, without acting on the linear (and, inside, the
    // quadratic) pressure fields that loads impose at impermeable walls.
    s.filter = fl.filter * fl.saturation * stabilisation_time_ / rho;
    const auto grad = gradient_matrices<Dim>(op_nn_, static_cast<Index>(nn));
    const NodeLaplacian<Dim> plain = build_node_laplacian<Dim>(disc_.nodes, kernel_);
    const PorePressureSolver::Sparse tg = build_filter_gradient_part<Dim>(plain.symmetric, disc_.nodes.position, grad);
    pressure_ = std::make_unique<PorePressureSolver>(lap.full, lap.symmetric, pw_drained_, s, &plain.symmetric, &tg);
  } else {
    pressure_ = std::make_unique<PorePressureSolver>(lap.full, lap.symmetric, pw_drained_, s);
  }
}

template <int Dim>
void StaggeredSolver<Dim>::pressure_step(double t_new) {
  const auto t0 = std::chrono::steady_clock::now();
  const Index nn = disc_.nodes.size();
  const double sw = setup_.fluid.saturation;
  const double inv_q_dt = inv_storage_ / dt_;
  pw_old_ = pw_;
  const Index* base = op_nn_.base.data();
  const Index* pat = op_nn_.pattern.data();
  const Index* pstart = op_nn_.pattern_start.data();
  const Index* off = op_nn_.offset.data();
  const auto* wg = op_nn_.grad.data();
  double* phi = node_phi_.data();
  // Same-set corrected gradient of a nodal scalar at node i (that of the velocity correction).
  auto node_gradient = [&](const std::vector<double>& f, Index i, double (&g)[Dim]) {
    for (int d = 0; d < Dim; ++d) g[d] = 0.0;
    for (Index k = pstart[pat[i]]; k < pstart[pat[i] + 1]; ++k) {
      const double fk = f[static_cast<std::size_t>(base[i] + off[k])];
      for (int d = 0; d < Dim; ++d) g[d] += wg[k][static_cast<std::size_t>(d)] * fk;
    }
  };
  // RHS_I = p^n_I/(Q* dt) - S_w (div v*)_I; drained nodes take their value at t^{n+1}.
  //
  // solver.pressure_divergence = "stress_points": div of the stress points' pressure-free half-
  // step velocity v~_E = P_EN v^n + (dt/2)(div sigma'/rho + b), gradient back to the nodes, with
  // the stabilisation S_w (dt/2)/rho in K. In a quasi-static state v~ = v + (dt/2) grad p/rho,
  // so the two (dt/2) terms cancel as the dt terms of METHOD.md §2.4 do; and when the stress
  // points are at rest the source is (dt/2) div grad p/rho, cancelled by K, so p_w drains to
  // zero. With div v* at the nodes it does not where a load jumps (a footing edge): there the
  // nodes keep an O(dt) velocity in the steady state that no stress point sees (docs/method-
  // notes.md, "Displacements"), and its divergence feeds a steady Darcy flow (Case 15: 0.2 sigma0
  // that never drains). Half the stabilisation damps odd-even pressure modes less (Case 16).
  const bool from_stress_points = !elem_v_skeleton_.empty();
#pragma omp parallel for schedule(static) if (nn > kParallelMinV3)
  for (Index i = 0; i < nn; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    double div = 0.0;
    if (from_stress_points) {
      const auto r = op_ne_.row(i);
      for (Index k = r.begin; k < r.end; ++k) {
        const double* v = &elem_v_skeleton_[static_cast<std::size_t>(op_ne_.source(r, k)) * Dim];
        for (int d = 0; d < Dim; ++d) div += op_ne_.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)] * v[d];
      }
    } else {
      for (Index k = pstart[pat[i]]; k < pstart[pat[i] + 1]; ++k) {
        const double* v = phi + static_cast<std::size_t>(base[i] + off[k]) * NV;
        for (int d = 0; d < Dim; ++d) div += wg[k][static_cast<std::size_t>(d)] * v[d];
      }
    }
    pw_source_[iu] = pw_old_[iu] * inv_q_dt - sw * div;
    if (pw_drained_[iu]) pw_[iu] = pw_value_[iu] * setup_.function_value(pw_function_[iu], t_new);
  }
  if (!pw_grad_.empty()) {
    // Incremental projection (solver.pressure_incremental): add S_w dt div(grad p^n / rho) to the
    // source; the solver subtracts S_w (dt/rho) L p^n, so the stabilisation acts on p^{n+1} - p^n.
    // At a static state (v^{n+1} = 0) the pressure equation then reduces to k_w L p = 0: the
    // mirror (impermeable) rows of L no longer constrain the hydrostatic-like gradient that
    // carries the load, which in the non-incremental form leaks pore pressure through the walls.
#pragma omp parallel for schedule(static) if (nn > kParallelMinV3)
    for (Index i = 0; i < nn; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      double g[Dim];
      node_gradient(pw_old_, i, g);
      for (int d = 0; d < Dim; ++d) pw_grad_[iu * Dim + static_cast<std::size_t>(d)] = g[d] / disc_.nodes.density[iu];
    }
    // A prescribed velocity component is not corrected (apply_constraints resets it), so it
    // carries no pressure-gradient term in v* - (dt/rho) grad p^n either.
    for (const Index i : constrained_nodes_) {
      const auto iu = static_cast<std::size_t>(i);
      for (Index k = constraint_row_[iu]; k < constraint_row_[iu + 1]; ++k) {
        const NodalConstraint& c = constraints_[static_cast<std::size_t>(k)];
        if (c.component < Dim) pw_grad_[iu * Dim + static_cast<std::size_t>(c.component)] = 0.0;
      }
    }
#pragma omp parallel for schedule(static) if (nn > kParallelMinV3)
    for (Index i = 0; i < nn; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      double div = 0.0;
      for (Index k = pstart[pat[i]]; k < pstart[pat[i] + 1]; ++k) {
        const double* g = &pw_grad_[static_cast<std::size_t>(base[i] + off[k]) * Dim];
        for (int d = 0; d < Dim; ++d) div += wg[k][static_cast<std::size_t>(d)] * g[d];
      }
      pw_source_[iu] += sw * stabilisation_time_ * div;
    }
  }
  pressure_->solve(pw_source_, pw_old_, pw_);
  // Velocity correction v^{n+1} = v* - (dt/rho) grad p^{n+1} (same-set corrected gradient).
#pragma omp parallel for schedule(static) if (nn > kParallelMinV3)
  for (Index i = 0; i < nn; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    double g[Dim];
    node_gradient(pw_, i, g);
    const double f = dt_ / disc_.nodes.density[iu];
    for (int d = 0; d < Dim; ++d) phi[iu * NV + static_cast<std::size_t>(d)] -= f * g[d];
  }
  pressure_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template void StaggeredSolver<1>::build_saturated();
template void StaggeredSolver<2>::build_saturated();
template void StaggeredSolver<1>::pressure_step(double);
template void StaggeredSolver<2>::pressure_step(double);

}  // namespace rktsph
