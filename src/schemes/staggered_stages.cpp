#include "schemes/staggered_stages.hpp"

#include "operators/free_surface.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "io/state_archive.hpp"
#include "materials/tensor.hpp"
#include "schemes/hourglass_control.hpp"
#include "operators/corrected_row.hpp"
#include "operators/run_sums.hpp"

namespace rktsph {

namespace {

// Rows of the on-the-fly operators evaluated together: one thread's block (its pair and
// degenerate counts summed once), and the unit the threads share out.
constexpr Index kOnTheFlyBlock = 256;

// A row's value (out[0]) and gradient (out[1 + d]) into the steps' layout: value[c] and
// grad[d][c] = d f_c / d x_d.
template <int Dim, int NF>
inline void split_value_gradient(const double (&out)[Dim + 1][NF], double (&value)[NF], double (&grad)[Dim][NF]) {
  for (int c = 0; c < NF; ++c) {
    value[c] = out[0][c];
    for (int d = 0; d < Dim; ++d) grad[d][c] = out[1 + d][c];
  }
}

// Where the on-the-fly rows of a step come from: each target's candidates, the targets, the
// sources' positions and volumes (at t^n), and the sources' velocity and stress.
template <int Dim>
struct OnTheFlySources {
  const Relation<Dim>& candidates;
  const std::vector<Vec<Dim>>& targets;
  const Vec<Dim>* position;
  const double* volume;
  const double* velocity;  // Dim values a source
  const double* stress;    // kStressComponents<Dim> values a source
};

// The rows [0, targets) of an operator evaluated on the fly (method-notes §5.2), in blocks of
// kOnTheFlyBlock shared out to the threads: each row is evaluated into the thread's
// CorrectedRow and use(row, a, v, grad_v, sigma, grad_sigma) gets the corrected value and
// gradient of the sources' velocity and stress at target a. The degenerate rows and the pairs
// are counted (integer sums: the same whatever the threads).
struct RowCounts {
  Index degenerate = 0;
  Index regularised = 0;  // by the gradient floor (method-notes eq. (3.2.6))
  std::size_t pairs = 0;
};
template <int Dim, class Use>
RowCounts rows_on_the_fly(const exec::Threads& policy, const OnTheFlySources<Dim>& from,
                          const CubicSplineKernel<Dim>& kernel, double r2, double gradient_floor, Use&& use) {
  constexpr int NS = kStressComponents<Dim>;
  const auto rows = static_cast<Index>(from.targets.size());
  const Index nblocks = (rows + kOnTheFlyBlock - 1) / kOnTheFlyBlock;
  std::atomic<Index> degenerate{0}, regularised{0};
  std::atomic<std::size_t> pairs{0};
  exec::particle_for(
      policy, nblocks,
      [&](Index blk) {
        static thread_local CorrectedRow<Dim> row;
        Index block_degenerate = 0, block_regularised = 0;
        std::size_t block_pairs = 0;
        const Index end = std::min(rows, (blk + 1) * kOnTheFlyBlock);
        for (Index a = blk * kOnTheFlyBlock; a < end; ++a) {
          if (!row.evaluate(from.candidates.row(a), from.targets[static_cast<std::size_t>(a)], from.position,
                            from.volume, kernel, r2, gradient_floor)) {
            ++block_degenerate;
          } else if (row.regularised()) {
            ++block_regularised;  // counted as the stored operators count it: degenerate first
          }
          block_pairs += row.size();
          double out_v[Dim + 1][Dim], out_s[Dim + 1][NS];
          row.template apply<Dim, NS>(from.velocity, from.stress, out_v, out_s);
          double v[Dim], grad_v[Dim][Dim], sigma[NS], grad_s[Dim][NS];
          split_value_gradient<Dim, Dim>(out_v, v, grad_v);
          split_value_gradient<Dim, NS>(out_s, sigma, grad_s);
          use(row, a, v, grad_v, sigma, grad_s);
        }
        if (block_degenerate > 0) degenerate.fetch_add(block_degenerate, std::memory_order_relaxed);
        if (block_regularised > 0) regularised.fetch_add(block_regularised, std::memory_order_relaxed);
        pairs.fetch_add(block_pairs, std::memory_order_relaxed);
      },
      exec::Schedule::even, rows);
  return {degenerate.load(), regularised.load(), pairs.load()};
}

// Row a's interpolation weights and sources kept for the nodal filters (MovingOperators).
template <int Dim>
inline void record_row(RecordedInterpolation<Dim>& record, const CorrectedRow<Dim>& row, Index a) {
  const std::size_t k0 = record.declare(a, row.size());
  std::copy(row.sources(), row.sources() + row.size(), record.source.begin() + static_cast<std::ptrdiff_t>(k0));
  row.value_weights(record.weight.data() + k0);
}

// V2 (method-notes §1.3, §5.2): particle i of `set` after its rotation over dt: the density by
// continuity with the velocity gradient grad_v, the volume from the mass, the position moved
// with the velocity v.
template <int Dim>
inline void continuity_and_move(ParticleSet<Dim>& set, std::size_t i, const double (&grad_v)[Dim][Dim], double dt,
                                const double* v) {
  double tr = 0.0;
  for (int k = 0; k < Dim; ++k) tr += grad_v[k][k];
  const double mass = set.volume[i] * set.density[i];
  set.density[i] /= 1.0 + dt * tr;
  set.volume[i] = mass / set.density[i];
  for (int d = 0; d < Dim; ++d) set.position[i][d] += dt * v[d];
}

}  // namespace

namespace {

// Velocity after tau of dv/dt = a - c_d v with the acceleration a = (1/rho) div sigma + b frozen
// over the step, integrated exactly (method-notes §4.2). The flux and the body force are damped
// together: a state in equilibrium (a = 0, v = 0) stays at rest whatever c_d tau. Damping only
// the source b and adding the flux undamped left the discrete equilibrium with div sigma =
// -rho b (1 - e^{-c_d tau})/(c_d tau): 2.4 % of the weight unsupported in Case 4(a), c_d tau = 0.05.
inline double damped_velocity(double v0, double a, double cd, double tau) {
  if (cd == 0.0) return v0 + a * tau;
  const double decay = -std::expm1(-cd * tau);  // 1 - e^{-c_d tau}
  return v0 - decay * v0 + a * decay / cd;
}

// The balance of momentum (method-notes eq. (1.2.1)): dv_i/dt = (1/rho) d sigma_ij / dx_j, from
// grad_s[d][s], the derivative along axis d of stress slot s.
template <int Dim>
inline void momentum_rate(const double (&grad_s)[Dim][kStressComponents<Dim>], double inv_rho, double* dv) {
  for (int i = 0; i < Dim; ++i) {
    double div = 0.0;
    for (int d = 0; d < Dim; ++d) div += grad_s[d][stress_slot<Dim>(i, d)];
    dv[i] = div * inv_rho;
  }
}

}  // namespace

// ---- sources

template <int Dim>
ViscoplasticSources<Dim>::ViscoplasticSources(StaggeredModel<Dim>& model) : model_(model) {
  if (model.materials.any_source) {
    const auto n = static_cast<std::size_t>(std::max(model.nodes.size(), model.stress_points.size()));
    sigma_start_.assign(n * NS, 0.0);
    rate_.assign(n * NS, 0.0);
  }
}

template <int Dim>
void ViscoplasticSources<Dim>::integrate(double tau, const SourceRuns& runs, FieldView<double, NS> stress,
                                         FieldView<double, 0> history) {
  const auto stride = static_cast<std::size_t>(history.components());
  if (run_stats_.size() < runs.size()) run_stats_.resize(runs.size());  // grows once per run list
  const auto start = std::chrono::steady_clock::now();
  // Per run (not per particle): the runs are few and of uneven cost (sub-stepping), so threads
  // pay off from a handful of runs on.
  exec::particle_for(
      exec::Threads{4}, static_cast<Index>(runs.size()),
      [&](Index r) {
        const auto [m, begin, end] = runs[static_cast<std::size_t>(r)];
        SourceBatch batch;
        batch.count = static_cast<std::size_t>(end - begin);
        batch.stress_components = NS;
        batch.sigma_start = sigma_start(begin);
        batch.sigma_start_stride = NS;
        batch.flux_rate = flux_rate(begin);
        batch.flux_rate_stride = NS;
        batch.sigma_end = stress[begin];
        batch.sigma_end_stride = NS;
        batch.state_start = history[begin];
        batch.state_end = history[begin];
        batch.state_stride = stride;
        batch.coupling = model_.setup.coupling;
        run_stats_[static_cast<std::size_t>(r)] = model_.materials[m].advance_source(tau, batch);
      },
      exec::Schedule::dynamic);
  for (std::size_t r = 0; r < runs.size(); ++r) stats_.add(run_stats_[r]);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <int Dim>
void ViscoplasticSources<Dim>::integrate_dissipating(double tau, const SourceRuns& runs, FieldView<double, NS> stress,
                                                     FieldView<double, 0> history, const std::vector<double>& volume) {
  integrate(tau, runs, stress, history);
  if (run_dissipation_.size() < runs.size()) run_dissipation_.resize(runs.size());
  // Per run in index order, then the runs in order: the same sum whatever the threads.
  exec::particle_for(
      exec::Threads{4}, static_cast<Index>(runs.size()),
      [&](Index r) {
        const auto [m, begin, end] = runs[static_cast<std::size_t>(r)];
        const ElasticConstants& el = model_.materials[m].elastic();
        double sum = 0.0;
        for (Index i = begin; i < end; ++i) {
          const double* start = sigma_start(i);
          const double* rate = flux_rate(i);
          Sym6 mid{}, drop{};
          for (int c = 0; c < NS; ++c) {
            const double trial = start[c] + tau * rate[c];
            mid[static_cast<std::size_t>(c)] = 0.5 * (stress(i, c) + trial);
            drop[static_cast<std::size_t>(c)] = trial - stress(i, c);
          }
          const Sym6 e = el.apply_inverse(drop);
          sum += volume[static_cast<std::size_t>(i)] * tensor::ddot(mid, e);
        }
        run_dissipation_[static_cast<std::size_t>(r)] = sum;
      },
      exec::Schedule::dynamic);
  for (std::size_t r = 0; r < runs.size(); ++r) dissipation_ += run_dissipation_[r];
}

template <int Dim>
void ViscoplasticSources<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "max_source_substeps", stats_.max_substeps);
  a.put_integer(prefix + "source_rk4_substeps", stats_.total_substeps);
  a.put_integer(prefix + "source_elastic_points", stats_.elastic_points);
  a.put_integer(prefix + "source_rk4_points", stats_.rk4_points);
  a.put_integer(prefix + "source_implicit_points", stats_.implicit_points);
  a.put_integer(prefix + "source_newton_iterations", stats_.newton_iterations);
  a.put_integer(prefix + "source_max_newton_iterations", stats_.max_newton_iterations);
  a.put_integer(prefix + "source_max_implicit_pieces", stats_.max_implicit_pieces);
  a.put(prefix + "plastic_dissipation", dissipation_);
}

template <int Dim>
void ViscoplasticSources<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  // Checkpoints written before the implicit source carry the sub-steps alone.
  auto count = [&](const std::string& key) { return a.has(prefix + key) ? static_cast<long>(a.integer(prefix + key)) : 0L; };
  stats_ = SourceStats{};
  stats_.max_substeps = count("max_source_substeps");
  stats_.total_substeps = count("source_rk4_substeps");
  stats_.elastic_points = count("source_elastic_points");
  stats_.rk4_points = count("source_rk4_points");
  stats_.implicit_points = count("source_implicit_points");
  stats_.newton_iterations = count("source_newton_iterations");
  stats_.max_newton_iterations = count("source_max_newton_iterations");
  stats_.max_implicit_pieces = count("source_max_implicit_pieces");
  dissipation_ = a.has(prefix + "plastic_dissipation") ? a.number(prefix + "plastic_dissipation") : 0.0;
}

// ---- step 1

template <int Dim, class PressureTerm, class Motion>
StressPointHalfStep<Dim, PressureTerm, Motion>::StressPointHalfStep(StaggeredModel<Dim>& model,
                                                                    std::shared_ptr<ViscoplasticSources<Dim>> sources,
                                                                    PressureTerm pressure)
    : m_(model), sources_(std::move(sources)), pressure_(pressure) {}

template <int Dim, class PressureTerm, class Motion>
void StressPointHalfStep<Dim, PressureTerm, Motion>::run(const StepContext& c) {
  constexpr int NS = kStressComponents<Dim>;
  const double tau = 0.5 * c.dt;
  const Vec<Dim> body = m_.body_force(c.t + 0.5 * tau);
  double b[Dim];
  for (int d = 0; d < Dim; ++d) b[d] = body[d];
  const double cd = c.damping;
  const CorrectedOperator<Dim>& op = m_.to_stress_points;
  ParticleSet<Dim>& sp = m_.stress_points;
  const double dt = c.dt;
  // Shared row patterns (operators/corrected_operator.hpp): pair k of stress point e has the
  // source base[e] + off[k]; on a lattice the few patterns' weights stay in the L1 cache.
  const Index* base = op.base.data();
  const Index* pat = op.pattern.data();
  const Index* pstart = op.pattern_start.data();
  const Index* off = op.offset.data();
  const double* wi = op.interp.data();
  const auto node_v = std::as_const(m_.nodes).view(m_.fields.velocity);
  const auto node_s = std::as_const(m_.nodes).view(m_.fields.stress);
  const auto node_k = std::as_const(m_.nodes).view(m_.fields.history);
  auto sp_v = m_.stress_points.view(m_.fields.sp_velocity);
  auto sp_s = m_.stress_points.view(m_.fields.sp_stress);
  auto sp_k = m_.stress_points.view(m_.fields.sp_history);
  const int stride = sp_k.components();
  const bool sources = sources_->active();
  ViscoplasticSources<Dim>& src = *sources_;
  if constexpr (Motion::kMoving) src.reserve(sp.size());  // re-seeded stress points (V2)
  const PressureTerm& pressure = pressure_;
  // The update of stress point e from the interpolated nodal state (bar_v, bar_s), its gradient
  // and, in V3, the pressure gradient; history(ks) writes the interpolated history variables.
  auto update = [&](Index e, const double(&bar_v)[Dim], const double(&grad_v)[Dim][Dim], double(&bar_s)[NS],
                    const double(&grad_s)[Dim][NS], [[maybe_unused]] const double* grad_p, auto&& history) {
    const auto eu = static_cast<std::size_t>(e);
    const int mat = sp.material[eu];
    double dv[Dim], dsig[NS];
    momentum_rate<Dim>(grad_s, 1.0 / sp.density[eu], dv);
    // The moduli at the interpolated stress when they depend on it (method-notes eq. (1.8.8)).
    m_.materials.elastic[static_cast<std::size_t>(mat)](grad_v, bar_s, dsig);
    if constexpr (PressureTerm::kActive) {
      // V3 (method-notes §5.3): -grad p^n / rho in the stress points' half step.
      if (pressure.skeleton.data() != nullptr) {
        for (int i = 0; i < Dim; ++i) pressure.skeleton(e, i) = damped_velocity(bar_v[i], dv[i] + b[i], cd, tau);
      }
      const double inv_rho = 1.0 / sp.density[eu];
      for (int d = 0; d < Dim; ++d) dv[d] -= grad_p[d] * inv_rho;
    }
    for (int i = 0; i < Dim; ++i) sp_v(e, i) = damped_velocity(bar_v[i], dv[i] + b[i], cd, tau);
    if constexpr (Motion::kMoving) {
      // V2 (method-notes §1.3, §5.2): the Jaumann rotation of the interpolated stress over
      // the half step (the flux and the source then act on the rotated stress); the
      // density by continuity over the step, with d at t^n; the position with v^{n+1/2}.
      jaumann_rotate<Dim>(grad_v, tau, bar_s);
      continuity_and_move<Dim>(sp, eu, grad_v, dt, sp_v[e]);
    }
    for (int s = 0; s < NS; ++s) sp_s(e, s) = bar_s[s] + tau * dsig[s];
    if (sources) {
      double* start = src.sigma_start(e);
      double* rate = src.flux_rate(e);
      for (int s = 0; s < NS; ++s) {
        start[s] = bar_s[s];
        rate[s] = dsig[s];
      }
    }
    // History variables are interpolated from the nodes (method-notes §3.3: nodes are primary).
    if (stride > 0) history(sp_k[e]);
  };
  if constexpr (Motion::kMoving) {
    if (moving_ != nullptr && moving_->on_the_fly) {
      // V2, operators on the fly (method-notes §5.2): each stress point's row evaluated from its
      // candidates at the positions of t^n, which are kept for step 2 before the row moves.
      MovingOperators<Dim>& mo = *moving_;
      mo.resize(sp.size());
      const Relation<Dim>& candidates = *mo.nodes_near_stress_points;
      const ParticleSet<Dim>& nodes = m_.nodes;
      const OnTheFlySources<Dim> from{candidates,          sp.position,   nodes.position.data(),
                                      nodes.volume.data(), node_v.data(), node_s.data()};
      const bool record = mo.record_interpolation;
      if (record) mo.nodes_to_stress_points.prepare(candidates);
      const RowCounts counts = rows_on_the_fly<Dim>(
          m_.policy, from, m_.kernel, mo.r2, m_.setup.gradient_floor,
          [&](const CorrectedRow<Dim>& row, Index e, const double(&bar_v)[Dim], const double(&grad_v)[Dim][Dim],
              double(&bar_s)[NS], const double(&grad_s)[Dim][NS]) {
            const auto eu = static_cast<std::size_t>(e);
            mo.stress_point_position[eu] = sp.position[eu];
            mo.stress_point_volume[eu] = sp.volume[eu];
            if (record) record_row(mo.nodes_to_stress_points, row, e);
            update(e, bar_v, grad_v, bar_s, grad_s, nullptr,
                   [&](double* ks) { row.interpolate(node_k.data(), stride, ks); });
          });
      m_.to_stress_points.degenerate_rows = counts.degenerate;
      m_.to_stress_points.regularised_rows = counts.regularised;
      m_.to_stress_points.pair_count = counts.pairs;
      if (sources) src.integrate(tau, m_.stress_point_sources, sp_s, sp_k);
      return;
    }
  }
  exec::particle_for(
      m_.policy, op.runs(),
      [&](Index r) {
        // Interpolated state (slot 0) and its gradient (slots 1..Dim) of the run's stress points.
        double acc_v[Dim + 1][CorrectedOperator<Dim>::kMaxRun * Dim];
        double acc_s[Dim + 1][CorrectedOperator<Dim>::kMaxRun * NS];
        const Index e0 = op.run_start[static_cast<std::size_t>(r)], e1 = op.run_start[static_cast<std::size_t>(r) + 1];
        const Index k0 = pstart[pat[e0]], k1 = pstart[pat[e0] + 1];
        interpolate_run<Dim, Dim>(op, node_v.data(), r, acc_v);
        interpolate_run<Dim, NS>(op, node_s.data(), r, acc_s);
        [[maybe_unused]] double acc_p[Dim][CorrectedOperator<Dim>::kMaxRun];
        if constexpr (PressureTerm::kActive) gradient_run<Dim, 1>(op, pressure.pressure, r, acc_p);
        for (Index e = e0; e < e1; ++e) {
          const auto sv = static_cast<std::size_t>(e - e0) * Dim;
          const auto ss = static_cast<std::size_t>(e - e0) * NS;
          double bar_v[Dim], bar_s[NS];
          double grad_v[Dim][Dim], grad_s[Dim][NS];
          for (int k = 0; k < Dim; ++k) {
            bar_v[k] = acc_v[0][sv + static_cast<std::size_t>(k)];
            for (int d = 0; d < Dim; ++d) grad_v[d][k] = acc_v[1 + d][sv + static_cast<std::size_t>(k)];
          }
          for (int s = 0; s < NS; ++s) {
            bar_s[s] = acc_s[0][ss + static_cast<std::size_t>(s)];
            for (int d = 0; d < Dim; ++d) grad_s[d][s] = acc_s[1 + d][ss + static_cast<std::size_t>(s)];
          }
          [[maybe_unused]] double grad_p[Dim];
          if constexpr (PressureTerm::kActive) {
            for (int d = 0; d < Dim; ++d) grad_p[d] = acc_p[d][static_cast<std::size_t>(e - e0)];
          }
          update(e, bar_v, grad_v, bar_s, grad_s, grad_p, [&](double* ks) {
            for (int j = 0; j < stride; ++j) ks[j] = 0.0;
            for (Index k = k0; k < k1; ++k) {
              const double* kn = node_k[base[e] + off[k]];
              for (int j = 0; j < stride; ++j) ks[j] += wi[k] * kn[j];
            }
          });
        }
      },
      exec::Schedule::even, sp.size());
  if (sources) src.integrate(tau, m_.stress_point_sources, sp_s, sp_k);
}

// ---- step 2

template <int Dim, class Motion, class Velocity>
NodeFullStep<Dim, Motion, Velocity>::NodeFullStep(StaggeredModel<Dim>& model,
                                                  std::shared_ptr<ViscoplasticSources<Dim>> sources)
    : m_(model), sources_(std::move(sources)) {}

namespace {

// The stress gradient at a detected free-surface node (V2): sigma = P(sigma) + Q(sigma), with P
// the traction-free projection of method-notes §3.7 about the node's normal (at a corner: no
// in-plane stress; on a 3D edge: the stress along it alone) and Q = 1 - P the
// part that the condition prescribes (zero). As fix (a) of §0.3 item 1 does for a prescribed
// component, Q enters through the difference form with fhat = 0, P through the corrected
// gradient: grad sigma = P(grad_corrected sigma) + Q(sum_b c_b sigma_b).
template <int Dim>
void surface_stress_gradient(const typename StaggeredModel<Dim>::SurfaceRows& surface, Index row,
                             ConstFieldView<double, kStressComponents<Dim>> sp_s,
                             double (&grad_s)[Dim][kStressComponents<Dim>]) {
  constexpr int NS = kStressComponents<Dim>;
  const DifferenceGradient<Dim>& g = surface.gradient;
  const auto r = static_cast<std::size_t>(row);
  double sum[Dim][NS] = {};
  for (Index k = g.row_start[r]; k < g.row_start[r + 1]; ++k) {
    const double* s = sp_s[g.source[static_cast<std::size_t>(k)]];
    const Vec<Dim>& w = g.weight[static_cast<std::size_t>(k)];
    for (int d = 0; d < Dim; ++d) {
      for (int c = 0; c < NS; ++c) sum[d][c] += w[d] * s[c];
    }
  }
  const Vec<Dim>& n = surface.normal[r];
  const bool corner = surface.corner[r] != 0;
  const Vec<Dim> edge = surface.edge.empty() ? Vec<Dim>::Zero() : surface.edge[r];
  for (int d = 0; d < Dim; ++d) {
    double p[NS], q[NS];
    for (int c = 0; c < NS; ++c) {
      p[c] = grad_s[d][c];
      q[c] = sum[d][c];
    }
    make_surface_traction_free<Dim>(n, corner, edge, p);
    make_surface_traction_free<Dim>(n, corner, edge, q);  // P(sum); Q(sum) = sum - P(sum)
    for (int c = 0; c < NS; ++c) grad_s[d][c] = p[c] + (sum[d][c] - q[c]);
  }
}

// The velocity gradient at a node in contact with a rigid body (V2, method-notes §4.5): the
// components the contact prescribes enter their own gradient through the difference form with
// fhat = the body's velocity (fix (a) of §0.3 item 1), the others keep the corrected gradient.
// Held in full (stick, two bodies): every component; else the normal one, v.n.
template <int Dim>
void contact_velocity_gradient(const typename StaggeredModel<Dim>::ContactRows& contact, Index row,
                               ConstFieldView<double, Dim> sp_v, double (&grad_v)[Dim][Dim]) {
  const DifferenceGradient<Dim>& g = contact.gradient;
  const auto r = static_cast<std::size_t>(row);
  const Vec<Dim>& fhat = contact.velocity[r];
  double diff[Dim][Dim] = {};
  for (Index k = g.row_start[r]; k < g.row_start[r + 1]; ++k) {
    const double* v = sp_v[g.source[static_cast<std::size_t>(k)]];
    const Vec<Dim>& w = g.weight[static_cast<std::size_t>(k)];
    for (int d = 0; d < Dim; ++d) {
      for (int q = 0; q < Dim; ++q) diff[d][q] += w[d] * v[q];
    }
  }
  for (int d = 0; d < Dim; ++d) {
    for (int q = 0; q < Dim; ++q) diff[d][q] -= g.weight_sum[r][d] * fhat[q];
  }
  if (contact.full[r] != 0) {
    for (int d = 0; d < Dim; ++d) {
      for (int q = 0; q < Dim; ++q) grad_v[d][q] = diff[d][q];
    }
    return;
  }
  const Vec<Dim>& n = contact.normal[r];
  for (int d = 0; d < Dim; ++d) {
    double change = 0.0;  // n . (diff - corrected) along axis d
    for (int q = 0; q < Dim; ++q) change += n[q] * (diff[d][q] - grad_v[d][q]);
    for (int q = 0; q < Dim; ++q) grad_v[d][q] += n[q] * change;
  }
}

}  // namespace

template <int Dim, class Motion, class Velocity>
void NodeFullStep<Dim, Motion, Velocity>::run(const StepContext& c) {
  constexpr int NS = kStressComponents<Dim>;
  const double dt = c.dt;
  const Vec<Dim> body = m_.body_force(c.t + 0.5 * dt);
  double b[Dim];
  for (int d = 0; d < Dim; ++d) b[d] = body[d];
  const double cd = c.damping;
  const double simple_weight = m_.setup.simple_weight;
  const double stress_weight = m_.setup.simple_stress_weight;
  const double t_half = c.t + 0.5 * dt;
  const CorrectedOperator<Dim>& op = m_.to_nodes;
  ParticleSet<Dim>& nodes = m_.nodes;
  const auto sp_v = std::as_const(m_.stress_points).view(m_.fields.sp_velocity);
  const auto sp_s = std::as_const(m_.stress_points).view(m_.fields.sp_stress);
  auto node_v = m_.nodes.view(m_.fields.velocity);
  auto node_s = m_.nodes.view(m_.fields.stress);
  auto node_u = m_.nodes.view(m_.fields.displacement);
  const NodalConstraints<Dim>& constraints = m_.constraints;
  const DifferenceGradient<Dim>& diff = m_.constrained_gradient;
  const bool sources = sources_->active();
  ViscoplasticSources<Dim>& src = *sources_;
  HourglassControl<Dim>* hourglass = hourglass_.get();
  if (hourglass != nullptr) hourglass->reserve(nodes.size());
  // The hourglass pass after the nodes' update, before their source (method-notes §2.6).
  auto control_hourglass = [&] {
    if (hourglass == nullptr) return;
    const auto t0 = std::chrono::steady_clock::now();
    hourglass->apply(dt, *hourglass_pairs_, node_v, node_s, sources ? src.flux_rate(0) : nullptr);
    hourglass_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    hourglass_kinetic_ += hourglass->kinetic_change();
    hourglass_strain_ += hourglass->strain_change();
    hourglass_dissipation_ += dt * hourglass->dissipation();
    hourglass_exchange_ += dt * hourglass->exchange();
    hourglass_theta_ = std::max(hourglass_theta_, hourglass->theta_max());
  };
  // The update of node i from the gradients of the stress points' state and their velocity
  // interpolated back (v_half, the material velocity at t^{n+1/2}).
  auto update = [&](Index i, double(&grad_v)[Dim][Dim], double(&grad_s)[Dim][NS], double(&v_half)[Dim],
                    bool irregular_row, const double(&s_half)[NS]) {
    const auto iu = static_cast<std::size_t>(i);
    if (volumetric_rate_ != nullptr) {
      // The stress points' divergence by the corrected gradient, before fix (a) replaces a
      // prescribed component's gradient below (V3's storage equation, eq. (2.4.20)).
      double tr = 0.0;
      for (int k = 0; k < Dim; ++k) tr += grad_v[k][k];
      volumetric_rate_[iu] = tr;
    }
    for (Index q = constraints.begin(i); q < constraints.end(i); ++q) {
      const NodalConstraint& con = constraints[q];
      if (con.component < Dim) v_half[con.component] = m_.constraint_value(i, con, t_half);
    }
    const Index drow = constraints.constrained_row(i);
    if (drow >= 0) {
      // method-notes §0.3 fix (a): a prescribed component enters its own gradient through
      // the difference form with fhat = the prescribed value at t^{n+1/2}.
      const auto dr = static_cast<std::size_t>(drow);
      for (Index q = constraints.begin(i); q < constraints.end(i); ++q) {
        const NodalConstraint& con = constraints[q];
        if (m_.released_by_contact(i, con)) continue;
        const double fhat = m_.constraint_value(i, con, t_half);
        const bool is_velocity = con.component < Dim;
        const int comp = is_velocity ? con.component : con.component - Dim;
        double g[Dim] = {};
        for (Index k = diff.row_start[dr]; k < diff.row_start[dr + 1]; ++k) {
          const Index e = diff.source[static_cast<std::size_t>(k)];
          const double f = is_velocity ? sp_v(e, comp) : sp_s(e, comp);
          for (int d = 0; d < Dim; ++d) g[d] += diff.weight[static_cast<std::size_t>(k)][d] * f;
        }
        for (int d = 0; d < Dim; ++d) {
          const double value = g[d] - diff.weight_sum[dr][d] * fhat;
          if (is_velocity) {
            grad_v[d][comp] = value;
          } else {
            grad_s[d][comp] = value;
          }
        }
      }
    }
    if (!m_.surface.row.empty() && m_.surface.row[iu] >= 0) {
      surface_stress_gradient<Dim>(m_.surface, m_.surface.row[iu], sp_s, grad_s);
      if (!m_.surface.traction.empty()) {
        // A prescribed traction (polygon edges, method-notes §3.9): the difference form
        // with fhat = the stress it prescribes, as fix (a) of §0.3 item 1.
        const auto srow = static_cast<std::size_t>(m_.surface.row[iu]);
        double prescribed[NS] = {};
        m_.add_surface_traction(srow, t_half, prescribed);
        for (int d = 0; d < Dim; ++d) {
          for (int k = 0; k < NS; ++k) grad_s[d][k] -= m_.surface.gradient.weight_sum[srow][d] * prescribed[k];
        }
      }
    }
    if (!m_.contact.row.empty() && m_.contact.row[iu] >= 0) {
      contact_velocity_gradient<Dim>(m_.contact, m_.contact.row[iu], sp_v, grad_v);
    }
    const int mat = nodes.material[iu];
    double dv[Dim], dsig[NS];
    momentum_rate<Dim>(grad_s, 1.0 / nodes.density[iu], dv);
    // The moduli at the node's stress at t^n when they depend on it (method-notes eq. (1.8.8)).
    m_.materials.elastic[static_cast<std::size_t>(mat)](grad_v, node_s[i], dsig);
    double* v = node_v[i];
    double* s = node_s[i];
    double v_n[Dim];
    for (int d = 0; d < Dim; ++d) v_n[d] = v[d];
    if constexpr (Velocity::kSimple) {
      // The simple scheme (method-notes §2.3): from the stress points' velocity, half a step;
      // with a weight below 1, blended with V1's step 2 (eq. (2.3.2)).
      const bool flagged = !m_.surface.row.empty() && m_.surface.row[iu] >= 0;
      if (simple_weight == 1.0 || flagged || irregular_row) {
        for (int d = 0; d < Dim; ++d) v[d] = damped_velocity(v_half[d], dv[d] + b[d], cd, 0.5 * dt);
      } else {
        for (int d = 0; d < Dim; ++d)
          v[d] = simple_weight * damped_velocity(v_half[d], dv[d] + b[d], cd, 0.5 * dt) +
                 (1.0 - simple_weight) * damped_velocity(v[d], dv[d] + b[d], cd, dt);
      }
    } else {
      for (int d = 0; d < Dim; ++d) v[d] = damped_velocity(v[d], dv[d] + b[d], cd, dt);
    }
    if constexpr (Motion::kMoving) {
      // V2: the Jaumann rotation over the step with the spin of v^{n+1/2}; the density by
      // continuity; the position moved with the displacement (x - X = u).
      jaumann_rotate<Dim>(grad_v, dt, s);
      if (hourglass != nullptr) {
        // What the hourglass control reads (method-notes eq. (2.6.1)): x^n, v^n, the updated and
        // the simple scheme's velocities, L, the rotated stress plus half the step's flux, G.
        double s_tilde[NS];
        for (int k = 0; k < NS; ++k) s_tilde[k] = s[k] + 0.5 * dt * dsig[k];
        double v_simple[Dim];
        for (int d = 0; d < Dim; ++d) v_simple[d] = damped_velocity(v_half[d], dv[d] + b[d], cd, 0.5 * dt);
        // A lone node on the free surface (its row regularised or degenerate) takes the simple
        // scheme's velocity (eq. (2.6.4)): a smooth footing's edge squeezes such nodes out.
        const bool on_surface = !m_.surface.row.empty() && m_.surface.row[iu] >= 0;
        hourglass->record(i, nodes.position[iu], v_n, v, v_simple, grad_v, s_tilde, grad_s,
                          irregular_row && on_surface);
      }
      continuity_and_move<Dim>(nodes, iu, grad_v, dt, v_half);
    }
    if (sources) {
      double* start = src.sigma_start(i);
      double* rate = src.flux_rate(i);
      for (int k = 0; k < NS; ++k) {
        start[k] = s[k];
        rate[k] = dsig[k];
      }
    }
    for (int k = 0; k < NS; ++k) s[k] += dt * dsig[k];
    if (stress_weight > 0.0) {
      // eq. (2.3.3): blended with the simple scheme's stress, the stress points' stress at
      // t^{n+1/2} interpolated to the node, rotated over the second half step and advanced by
      // half a step's flux; the source then acts on the blend (its start moved with it).
      double simple[NS];
      for (int k = 0; k < NS; ++k) simple[k] = s_half[k];
      if constexpr (Motion::kMoving) jaumann_rotate<Dim>(grad_v, 0.5 * dt, simple);
      for (int k = 0; k < NS; ++k) {
        const double blended = s[k] + stress_weight * (simple[k] + 0.5 * dt * dsig[k] - s[k]);
        if (sources) src.sigma_start(i)[k] += blended - s[k];
        s[k] = blended;
      }
    }
    // Displacement by the midpoint rule (method-notes §0.3 item 8).
    for (int d = 0; d < Dim; ++d) node_u(i, d) += dt * v_half[d];
  };
  if constexpr (Motion::kMoving) {
    if (moving_ != nullptr && moving_->on_the_fly) {
      // V2, operators on the fly (method-notes §5.2): each node's row evaluated from its
      // candidates at the stress points' positions and volumes of t^n, kept by step 1.
      MovingOperators<Dim>& mo = *moving_;
      const Relation<Dim>& candidates = *mo.stress_points_near_nodes;
      const OnTheFlySources<Dim> from{
          candidates,  nodes.position, mo.stress_point_position.data(), mo.stress_point_volume.data(),
          sp_v.data(), sp_s.data()};
      const bool record = mo.record_interpolation;
      if (record) mo.stress_points_to_nodes.prepare(candidates);
      const RowCounts counts =
          rows_on_the_fly<Dim>(m_.policy, from, m_.kernel, mo.r2, m_.setup.gradient_floor,
                               [&](const CorrectedRow<Dim>& row, Index i, double(&v_half)[Dim],
                                   double(&grad_v)[Dim][Dim], double(&s_half)[NS], double(&grad_s)[Dim][NS]) {
                                 if (record) record_row(mo.stress_points_to_nodes, row, i);
                                 update(i, grad_v, grad_s, v_half, row.regularised() || row.degenerate(), s_half);
                               });
      m_.to_nodes.degenerate_rows = counts.degenerate;
      m_.to_nodes.regularised_rows = counts.regularised;
      m_.to_nodes.pair_count = counts.pairs;
      moving_->note_rows(m_.degenerate_operator_rows(), m_.regularised_operator_rows(), c.t);
      control_hourglass();
      if (sources) src.integrate_dissipating(dt, m_.node_sources, node_s, m_.nodes.view(m_.fields.history), nodes.volume);
      return;
    }
  }
  exec::particle_for(
      m_.policy, op.runs(),
      [&](Index r) {
        // Interpolation (slot 0: the velocity for the displacement) and gradient of the stress
        // points' state at the run's nodes.
        double acc_v[Dim + 1][CorrectedOperator<Dim>::kMaxRun * Dim];
        double acc_s[Dim + 1][CorrectedOperator<Dim>::kMaxRun * NS];
        const Index i0 = op.run_start[static_cast<std::size_t>(r)], i1 = op.run_start[static_cast<std::size_t>(r) + 1];
        interpolate_run<Dim, Dim>(op, sp_v.data(), r, acc_v);
        interpolate_run<Dim, NS>(op, sp_s.data(), r, acc_s);
        for (Index i = i0; i < i1; ++i) {
          const auto sv = static_cast<std::size_t>(i - i0) * Dim;
          const auto ss = static_cast<std::size_t>(i - i0) * NS;
          double grad_v[Dim][Dim], grad_s[Dim][NS];
          for (int k = 0; k < Dim; ++k) {
            for (int d = 0; d < Dim; ++d) grad_v[d][k] = acc_v[1 + d][sv + static_cast<std::size_t>(k)];
          }
          for (int s = 0; s < NS; ++s) {
            for (int d = 0; d < Dim; ++d) grad_s[d][s] = acc_s[1 + d][ss + static_cast<std::size_t>(s)];
          }
          // The material velocity at t^{n+1/2} for the displacement: the stress points' velocity,
          // interpolated back. Not the nodal v, which in a steady state keeps an O(dt) component
          // the stress points never see (it balances the filter against the residual nodal
          // force: method-notes §0.3 item 8), and would make u drift.
          double v_half[Dim];
          for (int d = 0; d < Dim; ++d) v_half[d] = acc_v[0][sv + static_cast<std::size_t>(d)];
          // The stress points' stress at t^{n+1/2} at the node (eq. (2.3.3); unused at weight 0).
          double s_half[NS];
          for (int k = 0; k < NS; ++k) s_half[k] = acc_s[0][ss + static_cast<std::size_t>(k)];
          update(i, grad_v, grad_s, v_half,
                 (hourglass != nullptr || (Velocity::kSimple && simple_weight < 1.0)) && op.irregular(i), s_half);
        }
      },
      exec::Schedule::even, nodes.size());
  control_hourglass();
  if (sources) src.integrate_dissipating(dt, m_.node_sources, node_s, m_.nodes.view(m_.fields.history), nodes.volume);
}

template <int Dim, class Motion, class Velocity>
std::vector<std::pair<std::string, double>> NodeFullStep<Dim, Motion, Velocity>::report() const {
  if (hourglass_ == nullptr) return {};
  return {{"hourglass_seconds", hourglass_seconds_},
          {"hourglass_kinetic_change", hourglass_kinetic_},
          {"hourglass_strain_change", hourglass_strain_},
          {"hourglass_dissipation", hourglass_dissipation_},
          {"hourglass_exchange", hourglass_exchange_},
          {"hourglass_theta_max", hourglass_theta_}};
}

template <int Dim, class Motion, class Velocity>
void NodeFullStep<Dim, Motion, Velocity>::save(io::StateArchive& a, const std::string& prefix) const {
  sources_->save(a, prefix);
  if (hourglass_ != nullptr) {
    a.put(prefix + "hourglass_kinetic_change", hourglass_kinetic_);
    a.put(prefix + "hourglass_strain_change", hourglass_strain_);
    a.put(prefix + "hourglass_dissipation", hourglass_dissipation_);
    a.put(prefix + "hourglass_exchange", hourglass_exchange_);
    a.put(prefix + "hourglass_theta_max", hourglass_theta_);
  }
}

template <int Dim, class Motion, class Velocity>
void NodeFullStep<Dim, Motion, Velocity>::load(const io::StateArchive& a, const std::string& prefix) {
  sources_->load(a, prefix);
  if (hourglass_ != nullptr && a.has(prefix + "hourglass_kinetic_change")) {
    hourglass_kinetic_ = a.number(prefix + "hourglass_kinetic_change");
    hourglass_strain_ = a.number(prefix + "hourglass_strain_change");
    hourglass_dissipation_ = a.number(prefix + "hourglass_dissipation");
    hourglass_exchange_ = a.number(prefix + "hourglass_exchange");
    hourglass_theta_ = a.number(prefix + "hourglass_theta_max");
  }
}

// ---- checkerboard filters

namespace {

// The two interpolations the nodal filters apply, P_EN (nodes to stress points) and P_NE (back),
// from the model's stored operators (V1, V3, and V2 with solver.operators = "stored")...
template <int Dim>
struct StoredInterpolations {
  const CorrectedOperator<Dim>& en;
  const CorrectedOperator<Dim>& ne;

  template <int NC>
  void to_stress_points(const exec::Threads& policy, Index targets, const double* node_field, double* out) const {
    // By runs (run_sums): the vector loop over a run's contiguous sources.
    exec::particle_for(
        policy, en.runs(),
        [&](Index r) {
          double acc[CorrectedOperator<Dim>::kMaxRun * NC];
          double* sums[1] = {acc};
          const Index e0 = en.run_start[static_cast<std::size_t>(r)],
                      e1 = en.run_start[static_cast<std::size_t>(r) + 1];
          const auto e0u = static_cast<std::size_t>(e0);
          const auto p = static_cast<std::size_t>(en.pattern[e0u]);
          run_sums<1, 16>(
              node_field + static_cast<std::size_t>(en.base[e0u]) * NC, NC, static_cast<std::size_t>(e1 - e0) * NC,
              en.offset.data(), en.pattern_start[p], en.pattern_start[p + 1],
              [&](Index k, double* w) { w[0] = en.interp[static_cast<std::size_t>(k)]; }, sums);
          std::copy(acc, acc + static_cast<std::size_t>(e1 - e0) * NC, out + e0u * NC);
        },
        exec::Schedule::even, targets);
  }
  template <int NC>
  void at_node(Index i, const double* sp_field, double* acc) const {
    for (int c = 0; c < NC; ++c) acc[c] = 0.0;
    const auto row = ne.row(i);
    for (Index k = row.begin; k < row.end; ++k) {
      const double wk = ne.interp[static_cast<std::size_t>(k)];
      const double* p = sp_field + static_cast<std::size_t>(ne.source(row, k)) * NC;
      for (int c = 0; c < NC; ++c) acc[c] += wk * p[c];
    }
  }
};

// ... or from the weights V2's steps kept while they evaluated their rows on the fly
// (MovingOperators::record_interpolation): the same operators of t^n.
template <int Dim>
struct RecordedInterpolations {
  const RecordedInterpolation<Dim>& en;
  const RecordedInterpolation<Dim>& ne;

  template <int NC>
  static void row_sum(const RecordedInterpolation<Dim>& op, Index a, const double* field, double* acc) {
    for (int c = 0; c < NC; ++c) acc[c] = 0.0;
    for (std::size_t k = op.begin(a), k1 = op.end(a); k < k1; ++k) {
      const double wk = op.weight[k];
      const double* p = field + static_cast<std::size_t>(op.source[k]) * NC;
      for (int c = 0; c < NC; ++c) acc[c] += wk * p[c];
    }
  }
  template <int NC>
  void to_stress_points(const exec::Threads& policy, Index, const double* node_field, double* out) const {
    exec::particle_for(policy, en.rows(),
                       [&](Index e) { row_sum<NC>(en, e, node_field, out + static_cast<std::size_t>(e) * NC); });
  }
  template <int NC>
  void at_node(Index i, const double* sp_field, double* acc) const {
    row_sum<NC>(ne, i, sp_field, acc);
  }
};

// f <- f - eps (I - P_NE P_EN)^2 f on the nodal field f of NC values a node (method-notes §0.3
// item 3, eq. (2.3.4)): P_EN interpolates nodes to stress points, P_NE back. The mode that the
// stress points cannot see (P_EN f = 0) loses eps of itself; a linear field, which both
// interpolations reproduce, is left exactly; a smooth one changes at O(eps h^4). remove(i, f_i, r)
// takes eps r = eps [(I - P_NE P_EN)^2 f]_i, or the part of it the caller filters, from f_i (or
// from the field f was derived from).
template <int Dim, int NC, class Interpolations, class Remove>
void filter_nodal_checkerboard_with(const StaggeredModel<Dim>& m, const Interpolations& op, double* field,
                                    std::vector<double>& at_sp, std::vector<double>& at_nodes, Remove&& remove) {
  const Index ne = m.stress_points.size();
  const Index nn = m.nodes.size();
  // Re-seeded stress points (V2) change their count; otherwise this never allocates.
  if (at_sp.size() != static_cast<std::size_t>(ne) * NC) at_sp.assign(static_cast<std::size_t>(ne) * NC, 0.0);
  if (at_nodes.size() != static_cast<std::size_t>(nn) * NC) at_nodes.assign(static_cast<std::size_t>(nn) * NC, 0.0);
  FieldView<double, NC> filter_node(at_nodes.data(), nn, NC);
  FieldView<double, NC> f(field, nn, NC);
  op.template to_stress_points<NC>(m.policy, ne, field, at_sp.data());
  exec::particle_for(m.policy, nn, [&](Index i) {
    double acc[NC];
    op.template at_node<NC>(i, at_sp.data(), acc);
    for (int c = 0; c < NC; ++c) filter_node(i, c) = f(i, c) - acc[c];
  });
  op.template to_stress_points<NC>(m.policy, ne, filter_node.data(), at_sp.data());
  exec::particle_for(m.policy, nn, [&](Index i) {
    double acc[NC];
    op.template at_node<NC>(i, at_sp.data(), acc);
    for (int c = 0; c < NC; ++c) acc[c] = filter_node(i, c) - acc[c];
    remove(i, f[i], acc);
  });
}

// The filter with the interpolations of the step: recorded on the fly (V2's default) or stored.
template <int Dim, int NC, class Remove>
void filter_nodal_checkerboard(const StaggeredModel<Dim>& m, const MovingOperators<Dim>* moving, double* field,
                               std::vector<double>& at_sp, std::vector<double>& at_nodes, Remove&& remove) {
  if (moving != nullptr && moving->on_the_fly) {
    if (!moving->record_interpolation)
      throw std::logic_error("nodal filter on the fly: the steps were not asked to record their interpolations");
    // This step's rows: one a stress point and one a node (the scratch is sized by the sets).
    if (moving->nodes_to_stress_points.rows() != m.stress_points.size() ||
        moving->stress_points_to_nodes.rows() != m.nodes.size())
      throw std::logic_error("nodal filter on the fly: the recorded rows are not this step's particles");
    const RecordedInterpolations<Dim> op{moving->nodes_to_stress_points, moving->stress_points_to_nodes};
    filter_nodal_checkerboard_with<Dim, NC>(m, op, field, at_sp, at_nodes, std::forward<Remove>(remove));
  } else {
    const StoredInterpolations<Dim> op{m.to_stress_points, m.to_nodes};
    filter_nodal_checkerboard_with<Dim, NC>(m, op, field, at_sp, at_nodes, std::forward<Remove>(remove));
  }
}

}  // namespace

template <int Dim>
VelocityFilter<Dim>::VelocityFilter(StaggeredModel<Dim>& model, double strength)
    : m_(model),
      strength_(strength),
      at_stress_points_(static_cast<std::size_t>(model.stress_points.size()) * Dim, 0.0),
      at_nodes_(static_cast<std::size_t>(model.nodes.size()) * Dim, 0.0) {}

template <int Dim>
void VelocityFilter<Dim>::run(const StepContext&) {
  const double eps = strength_;
  filter_nodal_checkerboard<Dim, Dim>(m_, moving_, m_.nodes.view(m_.fields.velocity).data(), at_stress_points_,
                                      at_nodes_, [eps](Index, double* v, const double(&r)[Dim]) {
                                        for (int d = 0; d < Dim; ++d) v[d] -= eps * r[d];
                                      });
}

template <int Dim>
StressFilter<Dim>::StressFilter(StaggeredModel<Dim>& model, double strength, StressFilterPart part)
    : m_(model), strength_(strength), part_(part) {
  resize_scratch();
}

template <int Dim>
void StressFilter<Dim>::resize_scratch() {
  // The full tensor: NS values a particle; the mean stress: one.
  const std::size_t nc = part_ == StressFilterPart::full ? NS : 1;
  at_stress_points_.assign(static_cast<std::size_t>(m_.stress_points.size()) * nc, 0.0);
  at_nodes_.assign(static_cast<std::size_t>(m_.nodes.size()) * nc, 0.0);
  if (part_ == StressFilterPart::mean) mean_.assign(static_cast<std::size_t>(m_.nodes.size()), 0.0);
}

template <int Dim>
void StressFilter<Dim>::run(const StepContext&) {
  const auto t0 = std::chrono::steady_clock::now();
  filter();
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <int Dim>
void StressFilter<Dim>::filter() {
  const double eps = strength_;
  FieldView<double, NS> stress = m_.nodes.view(m_.fields.stress);
  if (part_ == StressFilterPart::full) {
    filter_nodal_checkerboard<Dim, NS>(m_, moving_, stress.data(), at_stress_points_, at_nodes_,
                                       [eps](Index, double* s, const double(&r)[NS]) {
                                         for (int k = 0; k < NS; ++k) s[k] -= eps * r[k];
                                       });
    return;
  }
  // The mean stress only (slots 0-2 are the normal components in every dimension): the
  // deviator, which a yield surface bounds and which carries the soil's strength, is left.
  // Both interpolations are linear, so the filter of the mean is the mean of the components'
  // filters (to round-off); filtered as one scalar a node, it costs a quarter of the tensor's.
  const Index nn = m_.nodes.size();
  if (mean_.size() != static_cast<std::size_t>(nn)) mean_.assign(static_cast<std::size_t>(nn), 0.0);
  exec::particle_for(m_.policy, nn, [&](Index i) {
    const double* s = stress[i];
    mean_[static_cast<std::size_t>(i)] = (s[0] + s[1] + s[2]) / 3.0;
  });
  filter_nodal_checkerboard<Dim, 1>(m_, moving_, mean_.data(), at_stress_points_, at_nodes_,
                                    [eps, &stress](Index i, double*, const double(&r)[1]) {
                                      double* s = stress[i];
                                      for (int k = 0; k < 3; ++k) s[k] -= eps * r[0];
                                    });
}

#define RKTSPH_INSTANTIATE(D)                                                 \
  template class ViscoplasticSources<D>;                                      \
  template class StressPointHalfStep<D, NoPressureGradient>;                  \
  template class StressPointHalfStep<D, PorePressureGradient<D>>;             \
  template class StressPointHalfStep<D, NoPressureGradient, MovingParticles>; \
  template class NodeFullStep<D>;                                             \
  template class NodeFullStep<D, MovingParticles, SimpleVelocity>;            \
  template class NodeFullStep<D, MovingParticles, TaylorGalerkinVelocity>;    \
  template class VelocityFilter<D>;                                           \
  template class StressFilter<D>;
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
