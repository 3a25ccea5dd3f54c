#include "schemes/pressure_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.hpp"
#include "io/state_archive.hpp"
#include "operators/laplacian.hpp"
#include "operators/run_sums.hpp"

namespace rktsph {

template <int Dim>
PorePressureStage<Dim>::PorePressureStage(StaggeredModel<Dim>& model) : m_(model) {
  const FluidSpec& fl = m_.setup.fluid;
  const ParticleSet<Dim>& nodes = m_.nodes;
  const auto nn = static_cast<std::size_t>(nodes.size());
  const double dt = m_.time_step.dt;
  pressure_ = m_.nodes.template add_field<double, 1>("pore_pressure", {"pw"}, kFieldOutput | kFieldEvolving);
  m_.set_pore_pressure(pressure_);
  auto pw = m_.nodes.view(pressure_);
  p_old_.assign(nn, 0.0);
  source_.assign(nn, 0.0);

  // Pore-pressure conditions (method-notes §4.1).
  conditions_ = resolve_pore_pressure_conditions<Dim>(m_.setup.boundaries, nodes, m_.boundary, m_.dx(),
                                                      m_.kernel.support_radius(), m_.setup.file);
  for (std::size_t i = 0; i < nn; ++i) {
    pw(static_cast<Index>(i), 0) = conditions_.drained[i]
                                       ? conditions_.value[i] * m_.function_value(conditions_.function[i], 0.0)
                                       : fl.initial_pore_pressure;
  }

  // The undrained Courant number and the faces where it limits stability (see the header).
  {
    const double q = 1.0 / fl.inverse_storage();
    double ratio = 1.0;
    for (const ElasticRate& e : m_.materials.elastic) {
      const double drained = e.lambda + 2.0 * e.G;
      ratio = std::max(ratio, std::sqrt((drained + q) / drained));
    }
    undrained_courant_ = m_.time_step.courant * ratio;
    impermeable_stress_faces_ = 0;
    for (std::size_t b = 0; b < m_.boundary.size(); ++b) {
      const Index i = m_.boundary.node[b];
      if (conditions_.drained[static_cast<std::size_t>(i)]) continue;
      bool exposed = false;
      for (int d = 0; d < Dim; ++d) {
        if ((m_.boundary.faces[b] >> (2 * d) & 3u) == 0) continue;  // not on a face normal to d
        bool held = false;
        for (Index k = m_.constraints.begin(i); k < m_.constraints.end(i); ++k)
          held = held || m_.constraints[k].component == d;
        exposed = exposed || !held;
      }
      if (exposed) ++impermeable_stress_faces_;
    }
  }

  Relation<Dim> relation;
  relation.build(nodes.position, nodes.position, operator_relation_options(m_.kernel), m_.policy);
  OperatorOptions options;
  options.gradient_floor = m_.setup.gradient_floor;
  node_operator_ = build_corrected_operator<Dim>(relation, nodes.position, nodes, m_.kernel, options);
  relation.build(nodes.position, nodes.position, laplacian_relation_options(m_.kernel), m_.policy);
  // The operators of the pressure system are built row by row into shared-pattern storage
  // (linear_solvers/pattern_matrix.hpp): no CSR copy of any of them at any time, so the set-up
  // peaks at a few hundred bytes per node above the V1 state (method-notes §5.3 "Storage").
  const NodeLaplacianPatterns lap =
      build_node_laplacian_patterns<Dim>(relation, nodes, m_.kernel, conditions_.planes, conditions_.mirror_mask);

  // K = I/(Q* dt) - k_eff S with k_eff = k_w + S_w dt/rho (method-notes §2.4). One mixture density
  // is assumed for the fractional-step term (the densest material: the largest stabilisation is
  // not needed, the smallest k_eff changes little; a single K keeps it symmetric).
  double rho = 0.0;
  for (const auto& mat : m_.materials.models) rho = std::max(rho, mat->density());
  inv_storage_ = fl.inverse_storage();
  PorePressureSolver::Settings s;
  s.inv_q_dt = inv_storage_ / dt;
  // The stabilisation time is dt with div v* at the nodes (method-notes §2.4) and dt/2 with the
  // stress points' half-step velocity, which carries (dt/2) grad p / rho in a quasi-static state.
  using StorageRate = FluidSpec::StorageRate;
  const bool pressure_free = fl.storage_rate == StorageRate::stress_points;
  stabilisation_time_ = pressure_free ? 0.5 * dt : dt;
  if (pressure_free) skeleton_.assign(static_cast<std::size_t>(m_.stress_points.size()) * Dim, 0.0);
  if (fl.storage_rate == StorageRate::consistent) {
    volumetric_rate_.assign(nn, 0.0);
    previous_divergence_.assign(nn, 0.0);
  }
  s.k_eff = fl.permeability() + fl.saturation * stabilisation_time_ / rho;
  s.tolerance = fl.tolerance;
  s.max_iterations = fl.max_iterations;
  s.preconditioner =
      fl.incomplete_cholesky ? PressurePreconditioner::incomplete_cholesky : PressurePreconditioner::diagonal;
  s.deferred_correction = fl.deferred_correction;
  if (fl.incremental) {
    s.incremental = fl.saturation * stabilisation_time_ / rho;
    pressure_gradient_.assign(nn * static_cast<std::size_t>(Dim), 0.0);
  }
  // The implicit face condition (method-notes eq. (2.4.16)); with the stress points' divergence
  // the storage equation reads the half-step velocity, which the coupling does not model. By
  // default only where the explicit form nears its limit: below, it is stable, and the
  // symmetric K keeps the conjugate gradient (BiCGSTAB costs 30-50 % more per step, BM_V3Step).
  using Faces = FluidSpec::FaceCondition;
  const bool implicit_faces =
      fl.face_condition == Faces::implicit ||
      (fl.face_condition == Faces::automatic && impermeable_stress_faces_ > 0 &&
       undrained_courant_ > auto_implicit_courant());
  if (implicit_faces && !pressure_free) {
    face_coupling_ = build_face_pressure_coupling<Dim>(m_, conditions_.drained, node_operator_, dt, fl.saturation);
  }
  const PorePressureSolver::Sparse* coupling = face_coupling_.empty() ? nullptr : &face_coupling_.storage_matrix;
  if (fl.filter > 0.0) {
    // Linear-exact pressure filter (solver.pressure_filter, operators/laplacian.hpp): tau (S_f p -
    // T G p) on the plain node set (no wall mirrors: psi_IJ pairs real nodes), G the corrected
    // node gradient of the velocity correction. It damps odd-even pressure modes, which the
    // incremental projection leaves undamped, without acting on the linear (and, inside, the
    // quadratic) pressure fields that loads impose at impermeable walls.
    s.filter = fl.filter * fl.saturation * stabilisation_time_ / rho;
    const NodeLaplacianPatterns plain = build_node_laplacian_patterns<Dim>(relation, nodes, m_.kernel, {}, {}, false);
    // The filter's gradient exact for quadratics on the truncated rows too (eq. (2.4.18)): with
    // the linear-exact one, psi_IJ is O(h^2 p'') there, and the filter drains the curved pressure
    // next to a drained face at a rate set by dt, not k (Mandel's problem, late times).
    PatternMatrix tg;
    using FilterGradient = FluidSpec::FilterGradient;
    if (fl.filter_gradient != FilterGradient::linear) {
      // quadratic_drained: the rows whose support holds a drained node (there the pressure is
      // pinned and its boundary layer curved; at impermeable faces the fit gains nothing and its
      // odd-even column makes the filter act harder on a shear band's pressure, VALIDATION.md).
      std::vector<char> near_drained;
      if (fl.filter_gradient == FilterGradient::quadratic_drained) {
        near_drained.assign(static_cast<std::size_t>(nn), 0);
        for (Index i = 0; i < static_cast<Index>(nn); ++i) {
          const auto r = node_operator_.row(i);
          for (Index k = r.begin; k < r.end; ++k) {
            if (conditions_.drained[static_cast<std::size_t>(node_operator_.source(r, k))]) {
              near_drained[static_cast<std::size_t>(i)] = 1;
              break;
            }
          }
        }
      }
      const CorrectedOperator<Dim> quadratic = quadratic_exact_gradient<Dim>(
          node_operator_, nodes.position, nodes, m_.kernel, m_.dx(),
          fl.filter_gradient == FilterGradient::quadratic_drained ? &near_drained : nullptr, &filter_fitted_rows_);
      tg = build_filter_gradient_patterns<Dim>(plain.symmetric, nodes.position, quadratic);
    } else {
      tg = build_filter_gradient_patterns<Dim>(plain.symmetric, nodes.position, node_operator_);
    }
    solver_ =
        std::make_unique<PorePressureSolver>(lap.full, lap.symmetric, conditions_.drained, s, &plain.symmetric, &tg, coupling);
  } else {
    solver_ = std::make_unique<PorePressureSolver>(lap.full, lap.symmetric, conditions_.drained, s, nullptr, nullptr,
                                                   coupling);
  }
  if (fl.odd_even_filter > 0.0) {
    if (!(m_.dx() > 0.0)) {
      throw InputError(fmt::format("{}: solver.pressure_odd_even_filter needs the nodes on a lattice of known spacing "
                                   "(geometry.spacing); set it to 0 and use solver.pressure_filter instead",
                                   m_.setup.file));
    }
    odd_even_weight_ = odd_even_amplitude<Dim>(node_operator_, nodes.position, nodes, m_.kernel, m_.dx());
    odd_even_amplitude_.assign(nn, 0.0);
  }
  if (m_.plates != nullptr && m_.plates->any_force()) {
    if (pressure_free) {
      throw InputError(fmt::format(
          "{}: a force-driven rigid body needs solver.pressure_divergence = \"consistent\" (the default) or "
          "\"nodes\": its "
          "velocity is eliminated from the storage equation through the nodal divergence (method-notes §4.6)",
          m_.setup.file));
    }
    couple_bodies();
  }
}

template <int Dim>
void PorePressureStage<Dim>::couple_bodies() {
  // method-notes eq. (4.6.3): the force-driven velocity of body j is V_j = V*_j + (dt/M_j) a_j.p
  // (the pore-pressure part of its reaction, implicit), and the storage equation sees it
  // through the nodal divergence, S_w d_j V_j. Eliminating V_j gives (K + sum_j u_j a_j^T) p = b
  // with u_j = S_w (dt/M_j) d_j: a low-rank update of K, solved by the Woodbury identity from
  // one ordinary solve a step and the z_j = K^{-1} u_j set up here (K does not change).
  if constexpr (Dim == 2) {
    const auto nn = static_cast<std::size_t>(m_.nodes.size());
    const double dt = m_.time_step.dt;
    const double sw = m_.setup.fluid.saturation;
    const CorrectedOperator<Dim>& op = node_operator_;
    std::vector<int> on_body(nn, -1);
    for (std::size_t b = 0; b < m_.plates->size(); ++b) {
      const RigidPlates::Plate& plate = m_.plates->plates()[b];
      for (const Index i : plate.nodes) on_body[static_cast<std::size_t>(i)] = static_cast<int>(b);
      for (int d = 0; d < 2; ++d) {
        if (!plate.spec.force_driven[static_cast<std::size_t>(d)]) continue;
        // Only a held component moves with the body (the normal one of a smooth body).
        if (d != plate.normal_axis && !plate.full) continue;
        BodyCoupling c;
        c.body = b;
        c.axis = d;
        c.gain = dt / plate.spec.mass;
        c.nodes = plate.nodes;
        for (std::size_t k = 0; k < plate.nodes.size(); ++k) c.weight.push_back(-plate.normal[d] * plate.length[k]);
        c.divergence.assign(nn, 0.0);
        bodies_.push_back(std::move(c));
      }
    }
    if (bodies_.empty()) return;
    for (BodyCoupling& c : bodies_) {
      for (std::size_t i = 0; i < nn; ++i) {
        double div = 0.0;
        const Index row = op.pattern[i];
        for (Index k = op.pattern_start[static_cast<std::size_t>(row)]; k < op.pattern_start[static_cast<std::size_t>(row) + 1]; ++k) {
          const auto j = static_cast<std::size_t>(op.base[i] + op.offset[static_cast<std::size_t>(k)]);
          if (on_body[j] == static_cast<int>(c.body)) div += op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(c.axis)];
        }
        c.divergence[i] = div;
      }
      std::vector<double> u(nn);
      for (std::size_t i = 0; i < nn; ++i) u[i] = sw * c.gain * c.divergence[i];
      c.z.assign(nn, 0.0);
      solver_->solve_matrix(u, c.z);
    }
    const auto m = static_cast<Eigen::Index>(bodies_.size());
    Eigen::MatrixXd g = Eigen::MatrixXd::Identity(m, m);
    for (Eigen::Index r = 0; r < m; ++r) {
      const BodyCoupling& a = bodies_[static_cast<std::size_t>(r)];
      for (Eigen::Index q = 0; q < m; ++q) {
        const BodyCoupling& z = bodies_[static_cast<std::size_t>(q)];
        for (std::size_t k = 0; k < a.nodes.size(); ++k) g(r, q) += a.weight[k] * z.z[static_cast<std::size_t>(a.nodes[k])];
      }
    }
    const Eigen::MatrixXd inv = g.inverse();
    body_inverse_.resize(static_cast<std::size_t>(m * m));
    for (Eigen::Index r = 0; r < m; ++r)
      for (Eigen::Index q = 0; q < m; ++q) body_inverse_[static_cast<std::size_t>(r * m + q)] = inv(r, q);
    body_dv_.assign(bodies_.size(), 0.0);
    body_w_.assign(bodies_.size(), 0.0);
  }
}

template <int Dim>
void PorePressureStage<Dim>::solve_with_bodies() {
  double* pw = m_.nodes.view(pressure_).data();
  const auto nn = static_cast<std::size_t>(m_.nodes.size());
  if (bodies_.empty()) {
    solver_->solve(source_, p_old_, {pw, nn});
    return;
  }
  const double sw = m_.setup.fluid.saturation;
  const std::size_t m = bodies_.size();
  // The drained nodes on a body: their p^{n+1} is known, so their part of dV_j is too.
  std::vector<double>& dv = body_dv_;
  for (std::size_t j = 0; j < m; ++j) {
    const BodyCoupling& c = bodies_[j];
    double known = 0.0;
    for (std::size_t k = 0; k < c.nodes.size(); ++k) {
      const auto i = static_cast<std::size_t>(c.nodes[k]);
      if (conditions_.drained[i]) known += c.weight[k] * pw[i];
    }
    dv[j] = c.gain * known;
    if (dv[j] != 0.0) {
      for (std::size_t i = 0; i < nn; ++i) source_[i] -= sw * c.divergence[i] * dv[j];
    }
  }
  solver_->solve(source_, p_old_, {pw, nn});
  // Woodbury: p = y - Z (I + W^T Z)^{-1} W^T y on the free nodes (z_j is zero at drained ones).
  // a_j . p over the body's free nodes (the drained ones are in dv already).
  auto free_part = [&](const BodyCoupling& c) {
    double sum = 0.0;
    for (std::size_t k = 0; k < c.nodes.size(); ++k) {
      const auto i = static_cast<std::size_t>(c.nodes[k]);
      if (!conditions_.drained[i]) sum += c.weight[k] * pw[i];
    }
    return sum;
  };
  std::vector<double>& w = body_w_;
  for (std::size_t j = 0; j < m; ++j) w[j] = free_part(bodies_[j]);
  for (std::size_t q = 0; q < m; ++q) {
    double cq = 0.0;
    for (std::size_t r = 0; r < m; ++r) cq += body_inverse_[q * m + r] * w[r];
    const std::vector<double>& z = bodies_[q].z;
    for (std::size_t i = 0; i < nn; ++i) pw[i] -= z[i] * cq;
  }
  for (std::size_t j = 0; j < m; ++j) {
    const BodyCoupling& c = bodies_[j];
    m_.plates->add_pressure_velocity(c.body, c.axis, dv[j] + c.gain * free_part(c));
  }
}

template <int Dim>
template <class Use>
void PorePressureStage<Dim>::each_node_divergence(const double* field, Use&& use) const {
  const CorrectedOperator<Dim>& op = node_operator_;
  exec::particle_for(
      m_.policy, op.runs(),
      [&](Index r) {
        double acc[Dim][CorrectedOperator<Dim>::kMaxRun * Dim];
        gradient_run<Dim, Dim>(op, field, r, acc);
        const Index i0 = op.run_start[static_cast<std::size_t>(r)];
        for (Index i = i0; i < op.run_start[static_cast<std::size_t>(r) + 1]; ++i) {
          double div = 0.0;
          for (int d = 0; d < Dim; ++d) div += acc[d][static_cast<std::size_t>(i - i0) * Dim + static_cast<std::size_t>(d)];
          use(i, div);
        }
      },
      exec::Schedule::even, m_.nodes.size());
}

template <int Dim>
void PorePressureStage<Dim>::record_node_divergence(bool initial_only) {
  if (previous_divergence_.empty() || (initial_only && previous_divergence_valid_)) return;
  each_node_divergence(std::as_const(m_.nodes).view(m_.fields.velocity).data(),
                       [&](Index i, double div) { previous_divergence_[static_cast<std::size_t>(i)] = div; });
  previous_divergence_valid_ = true;
}

template <int Dim>
std::string PorePressureStage<Dim>::instability_hint() const {
  const double limit = undrained_courant_limit();
  if (impermeable_stress_faces_ == 0 || undrained_courant_ <= limit || implicit_faces()) return {};
  return fmt::format(
      " (V3: impermeable faces carrying a total stress are unstable above C c_u/c_d = {}; "
      "here it is {:.2f}: time.cfl <= {:.3f})",
      limit, undrained_courant_, m_.time_step.courant * limit / undrained_courant_);
}

template <int Dim>
void PorePressureStage<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  const PorePressureSolver::WarmStart w = solver_->warm_start();
  a.put(prefix + "warm_start", w.previous);
  a.put_integer(prefix + "warm_start_valid", w.valid ? 1 : 0);
  const PressureSolveStats& s = solver_->stats();
  a.put(prefix + "stats", std::vector<double>{static_cast<double>(s.solves), static_cast<double>(s.total_iterations),
                                              static_cast<double>(s.max_iterations), static_cast<double>(s.last_iterations),
                                              s.last_error, s.max_error, s.seconds});
  a.put(prefix + "seconds", seconds_);
  if (!previous_divergence_.empty()) {
    a.put(prefix + "previous_divergence", previous_divergence_);
    a.put_integer(prefix + "previous_divergence_valid", previous_divergence_valid_ ? 1 : 0);
  }
}

template <int Dim>
void PorePressureStage<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  solver_->set_warm_start({a.doubles(prefix + "warm_start"), a.integer(prefix + "warm_start_valid") != 0});
  const auto& v = a.doubles(prefix + "stats");
  if (v.size() != 7) throw InputError("the checkpoint's pressure statistics are damaged");
  PressureSolveStats s;
  s.solves = static_cast<long>(v[0]);
  s.total_iterations = static_cast<long>(v[1]);
  s.max_iterations = static_cast<long>(v[2]);
  s.last_iterations = static_cast<int>(v[3]);
  s.last_error = v[4];
  s.max_error = v[5];
  s.seconds = v[6];
  solver_->set_stats(s);
  seconds_ = a.number(prefix + "seconds");
  if (!previous_divergence_.empty()) {
    const auto& d = a.doubles(prefix + "previous_divergence");
    if (d.size() != previous_divergence_.size()) throw InputError("the checkpoint's pressure state is damaged");
    previous_divergence_ = d;
    previous_divergence_valid_ = a.integer(prefix + "previous_divergence_valid") != 0;
  }
}

template <int Dim>
std::size_t PorePressureStage<Dim>::scratch_bytes() const {
  return (p_old_.size() + source_.size() + pressure_gradient_.size() + skeleton_.size() + odd_even_weight_.size() +
          odd_even_amplitude_.size() + volumetric_rate_.size() + previous_divergence_.size()) *
             sizeof(double) +
         node_operator_.bytes() + (solver_ != nullptr ? solver_->bytes() : 0) + face_coupling_.bytes();
}

template <int Dim>
void PorePressureStage<Dim>::run(const StepContext& context) {
  const auto t0 = std::chrono::steady_clock::now();
  const double t_new = context.t + context.dt;
  const double dt = m_.time_step.dt;
  const Index nn = m_.nodes.size();
  const ParticleSet<Dim>& nodes = m_.nodes;
  const double sw = m_.setup.fluid.saturation;
  const double inv_q_dt = inv_storage_ / dt;
  auto pw_view = m_.nodes.view(pressure_);
  std::vector<double>& pw_old = p_old_;
  std::copy(pw_view.data(), pw_view.data() + nn, pw_old.begin());
  const CorrectedOperator<Dim>& op = node_operator_;
  const Index* base = op.base.data();
  const Index* pat = op.pattern.data();
  const Index* pstart = op.pattern_start.data();
  const Index* off = op.offset.data();
  auto v = m_.nodes.view(m_.fields.velocity);
  double* pw = pw_view.data();
  // RHS_I = p^n_I/(Q* dt) - S_w (div v*)_I; drained nodes take their value at t^{n+1}.
  //
  // solver.pressure_divergence = "stress_points": div of the stress points' pressure-free half-
  // step velocity v~_E = P_EN v^n + (dt/2)(div sigma'/rho + b), gradient back to the nodes, with
  // the stabilisation S_w (dt/2)/rho in K. In a quasi-static state v~ = v + (dt/2) grad p/rho,
  // so the two (dt/2) terms cancel as the dt terms of method-notes §2.4 do; and when the stress
  // points are at rest the source is (dt/2) div grad p/rho, cancelled by K, so p_w drains to
  // zero. With div v* at the nodes it does not where a load jumps (a footing edge): there the
  // nodes keep an O(dt) velocity in the steady state that no stress point sees (method-notes
  // §0.3 item 8), and its divergence feeds a steady Darcy flow (Case 15: 0.2 sigma0 that never
  // drains). Half the stabilisation damps odd-even pressure modes less (Case 16).
  const bool from_stress_points = !skeleton_.empty();
  const CorrectedOperator<Dim>& to_nodes = m_.to_nodes;
  const FieldView<const double, Dim> skeleton(skeleton_.data(), m_.stress_points.size(), Dim);
  auto source_at = [&](Index i, double div) {
    const auto iu = static_cast<std::size_t>(i);
    source_[iu] = pw_old[iu] * inv_q_dt - sw * div;
    if (conditions_.drained[iu]) pw[iu] = conditions_.value[iu] * m_.function_value(conditions_.function[iu], t_new);
  };
  // The node operator's gradient of a scalar at every node, summed over runs of rows
  // (operators/run_sums.hpp), handed to `use` row by row (each_node_divergence likewise).
  auto each_gradient = [&](const double* field, auto&& use) {
    exec::particle_for(
        m_.policy, op.runs(),
        [&](Index r) {
          double acc[Dim][CorrectedOperator<Dim>::kMaxRun];
          gradient_run<Dim, 1>(op, field, r, acc);
          const Index i0 = op.run_start[static_cast<std::size_t>(r)];
          for (Index i = i0; i < op.run_start[static_cast<std::size_t>(r) + 1]; ++i) {
            double g[Dim];
            for (int d = 0; d < Dim; ++d) g[d] = acc[d][static_cast<std::size_t>(i - i0)];
            use(i, g);
          }
        },
        exec::Schedule::even, nn);
  };
  if (from_stress_points) {
    exec::particle_for(m_.policy, nn, [&](Index i) {
      double div = 0.0;
      const auto r = to_nodes.row(i);
      for (Index k = r.begin; k < r.end; ++k) {
        const double* ve = skeleton[to_nodes.source(r, k)];
        for (int d = 0; d < Dim; ++d)
          div += to_nodes.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)] * ve[d];
      }
      source_at(i, div);
    });
  } else {
    each_node_divergence(v.data(), source_at);
  }
  if (!pressure_gradient_.empty()) {
    // Incremental projection (solver.pressure_incremental): add S_w dt div(grad p^n / rho) to the
    // source; the solver subtracts S_w (dt/rho) L p^n, so the stabilisation acts on p^{n+1} - p^n.
    // At a static state (v^{n+1} = 0) the pressure equation then reduces to k_w L p = 0: the
    // mirror (impermeable) rows of L no longer constrain the hydrostatic-like gradient that
    // carries the load, which in the non-incremental form leaks pore pressure through the walls.
    FieldView<double, Dim> grad(pressure_gradient_.data(), nn, Dim);
    each_gradient(pw_old.data(), [&](Index i, const double* g) {
      const double inv_rho = 1.0 / nodes.density[static_cast<std::size_t>(i)];
      for (int d = 0; d < Dim; ++d) grad(i, d) = g[d] * inv_rho;
    });
    // A prescribed velocity component is not corrected (the constraints reset it), so it
    // carries no pressure-gradient term in v* - (dt/rho) grad p^n either.
    for (const Index i : m_.constraints.constrained()) {
      for (Index k = m_.constraints.begin(i); k < m_.constraints.end(i); ++k) {
        const NodalConstraint& c = m_.constraints[k];
        if (c.component < Dim) grad(i, c.component) = 0.0;
      }
    }
    each_node_divergence(grad.data(), [&](Index i, double div) {
      source_[static_cast<std::size_t>(i)] += sw * stabilisation_time_ * div;
    });
  }
  if (!previous_divergence_.empty()) {
    // Consistent storage rate (method-notes eq. (2.4.20)): S_w [(D v^n)_I - (D_N v^{n+1/2})_I] on
    // the right, D_N v^{n+1/2} the trace of step 2's corrected velocity gradient (the rate sigma'
    // integrates), so that the equation reads that rate plus the change of the node divergence
    // over the step, D v^{n+1} - D v^n, whose D v^{n+1} is the implicit part above. In a steady
    // state the nodes' O(dt) velocity that no stress point sees then cancels (Case 15: p_w drains
    // under the footing edge). D v^n is recorded by RecordNodeDivergence (D v^0 from the initial
    // velocity, so that the nodal terms telescope from the start).
    const double* rate = volumetric_rate_.data();
    const double* previous = previous_divergence_.data();
    exec::particle_for(m_.policy, nn, [&](Index i) {
      const auto iu = static_cast<std::size_t>(i);
      source_[iu] += sw * (previous[iu] - rate[iu]);
    });
  }
  solve_with_bodies();
  if (!odd_even_amplitude_.empty()) {
    // p <- p - alpha a (method-notes eq. (2.4.19)): the odd-even mode, which neither the nodal
    // gradient nor the stress points see inside the body, off p^{n+1}; drained nodes stay pinned.
    const double alpha = m_.setup.fluid.odd_even_filter;
    const double* w = odd_even_weight_.data();
    exec::particle_for(
        m_.policy, op.runs(),
        [&](Index r) {
          const Index a0 = op.run_start[static_cast<std::size_t>(r)], a1 = op.run_start[static_cast<std::size_t>(r) + 1];
          double* out[1] = {odd_even_amplitude_.data() + a0};
          run_sums<1, 8>(pw + base[a0], 1, static_cast<std::size_t>(a1 - a0), off, pstart[pat[a0]],
                          pstart[pat[a0] + 1], [&](Index k, double* wk) { wk[0] = w[k]; }, out);
        },
        exec::Schedule::even, nn);
    exec::particle_for(m_.policy, nn, [&](Index i) {
      const auto iu = static_cast<std::size_t>(i);
      if (!conditions_.drained[iu]) pw[iu] -= alpha * odd_even_amplitude_[iu];
    });
  }
  // Velocity correction v^{n+1} = v* - (dt/rho) grad p^{n+1} (same-set corrected gradient).
  each_gradient(pw, [&](Index i, const double* g) {
    const double f = dt / nodes.density[static_cast<std::size_t>(i)];
    for (int d = 0; d < Dim; ++d) v(i, d) -= f * g[d];
  });
  // The face condition at t^{n+1}: v += B (p^{n+1} - p^n) (method-notes eq. (2.4.16)).
  if (!face_coupling_.empty()) face_coupling_.add_velocity(v, pw, pw_old.data());
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template class PorePressureStage<1>;
template class PorePressureStage<2>;
template class PorePressureStage<3>;

}  // namespace rktsph
