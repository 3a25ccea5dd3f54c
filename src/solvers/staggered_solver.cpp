#include "solvers/staggered_solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "materials/uniaxial_stress.hpp"

namespace rktsph {

namespace {

// Stress slot of the tensor component (k, d) in the per-dimension storage (core/types.hpp).
template <int Dim>
constexpr int slot(int k, int d) {
  if (k == d) return k;
  const int lo = std::min(k, d), hi = std::max(k, d);
  if (lo == 0 && hi == 1) return 3;
  if (lo == 1 && hi == 2) return 4;
  return 5;
}

// Velocity after tau of dv/dt = a - c_d v with the acceleration a = (1/rho) div sigma + b frozen
// over the step, integrated exactly. The flux and the body force are damped together: a state
// in equilibrium (a = 0, v = 0) stays at rest whatever c_d tau. Damping only the source b and
// adding the flux undamped (the earlier form) left the discrete equilibrium with div sigma =
// -rho b (1 - e^{-c_d tau})/(c_d tau): 2.4 % of the weight unsupported in Case 4(a), c_d tau = 0.05.
inline double damped_velocity(double v0, double a, double cd, double tau) {
  if (cd == 0.0) return v0 + a * tau;
  const double decay = -std::expm1(-cd * tau);  // 1 - e^{-c_d tau}
  return v0 - decay * v0 + a * decay / cd;
}

// Flux rates at a point from the gradients of the state (METHOD.md §1.2):
//   dv_i/dt   = (1/rho) d sigma_ij / dx_j
//   dsigma/dt = lambda tr(d) 1 + 2 G d,  d = sym grad v
// grad[d][c] is the derivative along axis d of state component c.
template <int Dim>
inline void flux_rates(const double (&grad)[Dim][kStateComponents<Dim>], double inv_rho,
                       double lambda, double G, double* dv, double* dsig) {
  for (int i = 0; i < Dim; ++i) {
    double div = 0.0;
    for (int d = 0; d < Dim; ++d) div += grad[d][Dim + slot<Dim>(i, d)];
    dv[i] = div * inv_rho;
  }
  double tr = 0.0;
  for (int k = 0; k < Dim; ++k) tr += grad[k][k];
  for (int n = 0; n < 3; ++n) dsig[n] = lambda * tr + (n < Dim ? 2.0 * G * grad[n][n] : 0.0);
  for (int k = 0; k < Dim; ++k) {
    for (int d = k + 1; d < Dim; ++d) dsig[slot<Dim>(k, d)] = G * (grad[d][k] + grad[k][d]);
  }
}

constexpr Index kReductionBlock = 4096;  // fixed blocks: sums independent of the thread count
// Below this many particles a loop runs on one thread: the fork/join costs more than it saves.
constexpr Index kParallelMin = 2048;

// Sums over one run of an operator (CorrectedOperator::run_start): rows r0..r0+m-1 share a
// pattern and have consecutive bases, so pair k reads the same weights for every row, from the
// contiguous block src[(base + off[k]) * stride, ...) of len = m * stride doubles. Output q of
// slot i is
//   acc[q][i] = sum_k w_q[k] src[(base + off[k]) * stride + i],
// with weights(k, w) giving w_0..w_{NW-1} of pair k. The sum runs over k in pattern order for
// every slot, as a per-row loop would, but L slots at a time: the block loop is vector FMAs
// with NW * L / 8 independent accumulators in registers (enough to hide the FMA latency),
// where a per-row loop over a few state components does not vectorise.
template <int NW, std::size_t L, class Weights>
inline void run_sums(const double* src, std::size_t stride, std::size_t len, const Index* off, Index k0, Index k1,
                     Weights&& weights, double* const* acc) {
  std::size_t i0 = 0;
  auto block = [&](std::size_t width, auto fixed) {
    constexpr bool kFull = decltype(fixed)::value;
    double a[NW][L] = {};
    for (Index k = k0; k < k1; ++k) {
      const double* s = src + static_cast<std::size_t>(off[k]) * stride + i0;
      double w[NW];
      weights(k, w);
      if constexpr (kFull) {
        for (std::size_t l = 0; l < L; ++l) {
          for (int q = 0; q < NW; ++q) a[q][l] += w[q] * s[l];
        }
      } else {
        for (std::size_t l = 0; l < width; ++l) {
          for (int q = 0; q < NW; ++q) a[q][l] += w[q] * s[l];
        }
      }
    }
    for (int q = 0; q < NW; ++q) {
      for (std::size_t l = 0; l < width; ++l) acc[q][i0 + l] = a[q][l];
    }
  };
  for (; i0 + L <= len; i0 += L) block(L, std::true_type{});
  if (i0 < len) block(len - i0, std::false_type{});
}

// Interpolation (acc[0]) and gradient (acc[1..Dim]) of the NV-component field `src` at the
// targets of run r of `op` (step 1 from the nodes, step 2 from the stress points).
template <int Dim, int NV>
inline void interpolate_run(const CorrectedOperator<Dim>& op, const double* src, Index r,
                            double (&acc)[Dim + 1][CorrectedOperator<Dim>::kMaxRun * NV]) {
  const Index a0 = op.run_start[static_cast<std::size_t>(r)], a1 = op.run_start[static_cast<std::size_t>(r) + 1];
  const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a0)]);
  double* sums[Dim + 1];
  for (int q = 0; q <= Dim; ++q) sums[q] = acc[q];
  run_sums<Dim + 1, 16>(src + static_cast<std::size_t>(op.base[static_cast<std::size_t>(a0)]) * NV, NV,
                        static_cast<std::size_t>(a1 - a0) * NV, op.offset.data(), op.pattern_start[p],
                        op.pattern_start[p + 1], [&](Index k, double* w) {
                          w[0] = op.interp[static_cast<std::size_t>(k)];
                          for (int d = 0; d < Dim; ++d) w[1 + d] = op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
                        }, sums);
}

}  // namespace

template <int Dim>
StaggeredSolver<Dim>::StaggeredSolver(CaseSetup<Dim>& setup)
    : setup_(setup), kernel_(setup.h_over_dx * setup.dx) {
  materials_ = std::move(setup.materials);
  const bool uniaxial_stress = Dim == 1 && setup.condition == BarCondition::uniaxial_stress;
  std::vector<double> densities;
  for (auto& m : materials_) {
    densities.push_back(m->density());
    if (uniaxial_stress) {
      // CASES.md Case 2: scalar sigma with zero lateral stresses. The flux uses lambda = 0 and
      // 2G = E (axial modulus E, lateral stress rates zero) and the wave speed sqrt(E/rho);
      // the source sees (sxx, 0, 0) through the decorator (materials/uniaxial_stress.hpp).
      m = std::make_unique<UniaxialStressMaterial>(std::move(m));
      lambda_.push_back(0.0);
      shear_.push_back(0.5 * m->elastic().E);
      c_max_ = std::max(c_max_, std::sqrt(m->elastic().E / m->density()));
    } else {
      lambda_.push_back(m->elastic().lambda);
      shear_.push_back(m->elastic().G);
      c_max_ = std::max(c_max_, m->elastic().p_wave_speed());
    }
    any_source_ = any_source_ || m->has_source();
  }
  disc_ = discretise<Dim>(setup.blocks, setup.dx, setup.origin, densities);
  if (setup.scheme == Scheme::collocated) {
    // Single-set comparison scheme: the half-step lives on the nodes themselves.
    disc_.elements = disc_.nodes;
  }

  // Time step from the wave speed (METHOD.md §4.3 and §0.3 item 4).
  constexpr double kMaxCfl = 1.3;
  if (setup.dt) {
    dt_ = *setup.dt;
    cfl_ = dt_ * c_max_ / setup.dx;
  } else {
    cfl_ = *setup.cfl;
    dt_ = cfl_ * setup.dx / c_max_;
  }
  if (cfl_ > kMaxCfl) {
    throw InputError(fmt::format(
        "{}, key 'time.{}': the Courant number c dt/dx = {:.3f} exceeds {} (c = {:.4g} m/s, "
        "dx = {} m); the scheme is unstable beyond it (METHOD.md §0.3 item 4)",
        setup.file, setup.dt ? "dt" : "cfl", cfl_, kMaxCfl, c_max_, setup.dx));
  }

  // Operators, built once: particles do not move in V1.
  op_en_ = build_corrected_operator<Dim>(disc_.elements.position, disc_.nodes, kernel_);
  op_ne_ = build_corrected_operator<Dim>(disc_.nodes.position, disc_.elements, kernel_);

  // History variables: the union of the names of all materials.
  for (const auto& m : materials_) {
    state_stride_ = std::max(state_stride_, m->state_size());
    for (const auto& n : m->state_names()) {
      if (std::find(history_names_.begin(), history_names_.end(), n) == history_names_.end()) {
        history_names_.push_back(n);
      }
    }
  }
  for (const auto& m : materials_) {
    std::vector<int> slots(history_names_.size(), -1);
    const auto names = m->state_names();
    for (std::size_t i = 0; i < history_names_.size(); ++i) {
      for (std::size_t j = 0; j < names.size(); ++j) {
        if (names[j] == history_names_[i]) slots[i] = static_cast<int>(j);
      }
    }
    history_slot_.push_back(std::move(slots));
  }

  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  const auto ne = static_cast<std::size_t>(disc_.elements.size());
  node_phi_.assign(nn * NV, 0.0);
  elem_phi_.assign(ne * NV, 0.0);
  node_u_.assign(nn * Dim, 0.0);
  node_state_.assign(nn * static_cast<std::size_t>(state_stride_), 0.0);
  elem_state_.assign(ne * static_cast<std::size_t>(state_stride_), 0.0);
  v_half_.assign(nn * Dim, 0.0);
  filter_elem_.assign(ne * Dim, 0.0);
  filter_node_.assign(nn * Dim, 0.0);
  if (any_source_) {
    src_sigma_start_.assign(std::max(nn, ne) * NS, 0.0);
    src_rate_.assign(std::max(nn, ne) * NS, 0.0);
  }
  block_sums_.assign(((nn + kReductionBlock - 1) / kReductionBlock) * (Dim + 2), 0.0);

  // Runs of particles whose material has a source, cut into chunks for the threads.
  auto make_runs = [&](const ParticleSet<Dim>& set) {
    std::vector<std::array<Index, 3>> runs;
    constexpr Index kChunk = 512;
    Index i = 0;
    while (i < set.size()) {
      const int m = set.material[static_cast<std::size_t>(i)];
      Index j = i;
      while (j < set.size() && set.material[static_cast<std::size_t>(j)] == m && j - i < kChunk) ++j;
      if (materials_[static_cast<std::size_t>(m)]->has_source()) runs.push_back({m, i, j});
      i = j;
    }
    return runs;
  };
  node_runs_ = make_runs(disc_.nodes);
  elem_runs_ = make_runs(disc_.elements);

  build_constraints();
  if (setup.saturated) build_saturated();  // V3: pore pressure (staggered_saturated.cpp)
  set_initial_state();
}

template <int Dim>
void StaggeredSolver<Dim>::build_constraints() {
  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  std::vector<std::vector<NodalConstraint>> per_node(nn);
  // Bit k * Dim + d: v_k is prescribed at the node by an entry acting on the face with normal
  // e_d (an entry whose box is a plane x_d = const; a box that is no plane acts on every face).
  std::vector<std::uint16_t> velocity_on_face(nn, 0);
  const double tol = 1e-6 * setup_.dx + 1e-12;

  // Coverage of each constraint: 1, or the fraction of the node's face segment that a
  // prescribed traction covers (see below). Parallel to per_node.
  std::vector<std::vector<double>> coverage(nn);
  auto set = [&](std::size_t i, NodalConstraint c, double covered) {
    auto& list = per_node[i];
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (list[k].component != c.component) continue;
      if (covered < 1.0 && coverage[i][k] < 1.0 && list[k].function == c.function) {
        // Two partial loads meeting at the node (one ends where the next begins): they add.
        list[k].value += c.value;
        coverage[i][k] = std::min(1.0, coverage[i][k] + covered);
      } else {
        list[k] = c;  // a later [[boundary]] overrides an earlier one on the same component
        coverage[i][k] = covered;
      }
      return;
    }
    list.push_back(c);
    coverage[i].push_back(covered);
  };
  // A traction prescribed on part of a face acts on the nodes through their tributary face
  // segments [x - dx/2, x + dx/2] (half of it at an edge of the body): a node where the loaded
  // range ends gets the traction averaged over its segment, e.g. half the footing pressure at
  // the footing's edge. Taking the full value there widens the load by dx/2 and, being a jump
  // carried by one node, pushes on the mode the stress points cannot see (Case 15: edge
  // settlement +14 % at dx = 0.2 m, against +0.1 % with the average).
  auto traction_coverage = [&](const Region<Dim>& region, int normal_axis, std::size_t i) {
    const auto& x = disc_.nodes.position[i];
    const std::uint8_t faces = disc_.boundary.faces[i];
    double fraction = 1.0;
    for (int t = 0; t < Dim; ++t) {
      const auto tu = static_cast<std::size_t>(t);
      if (t == normal_axis || !region.bounded[tu] || region.hi[tu] - region.lo[tu] <= tol) continue;
      double lo = x[t] - 0.5 * setup_.dx, hi = x[t] + 0.5 * setup_.dx;
      if ((faces >> (2 * t)) & 1u) lo = x[t];       // the body ends on the -e_t side
      if ((faces >> (2 * t + 1)) & 1u) hi = x[t];   // ... on the +e_t side
      if (hi - lo <= tol) continue;
      const double covered = std::min(hi, region.hi[tu]) - std::max(lo, region.lo[tu]);
      fraction *= std::clamp(covered / (hi - lo), 0.0, 1.0);
    }
    return fraction;
  };

  for (const auto& spec : setup_.boundaries) {
    std::size_t selected = 0;
    unsigned planes = 0;
    for (std::size_t d = 0; d < Dim; ++d) {
      if (spec.region.bounded[d] && spec.region.hi[d] - spec.region.lo[d] <= tol) planes |= 1u << d;
    }
    if (planes == 0) planes = (1u << Dim) - 1u;
    for (std::size_t i = 0; i < nn; ++i) {
      if (!spec.region.contains(disc_.nodes.position[i], tol)) continue;
      ++selected;
      for (const auto& [axis, value] : spec.velocity) {
        set(i, {axis, value, spec.function}, 1.0);
        for (int d = 0; d < Dim; ++d) {
          if ((planes >> d) & 1u) velocity_on_face[i] = static_cast<std::uint16_t>(velocity_on_face[i] | (1u << (axis * Dim + d)));
        }
      }
      // A traction on a plane (one face) is averaged over the node's face segment; a box
      // that is no plane prescribes the stress as given.
      const bool on_plane = std::popcount(planes) == 1;
      const double covered = on_plane ? traction_coverage(spec.region, std::countr_zero(planes), i) : 1.0;
      for (const auto& [s, value] : spec.stress) set(i, {Dim + s, covered * value, spec.function}, covered);
    }
    if (selected == 0) {
      throw InputError(fmt::format("{}: boundary '{}' selects no node; check its ranges "
                                   "against the geometry",
                                   spec.where, spec.name));
    }
  }

  // Faces of the body are traction-free unless something else is prescribed (METHOD.md §4.1):
  // on a face with normal e_d, sigma_kd = 0 unless v_k is prescribed on THAT face, in which case
  // sigma_kd is its reaction and is not prescribed. A shear component shared by two faces is a
  // reaction only if neither face leaves it free. Where a fixed base meets a free face (the toe
  // of a cut, METHOD.md §0.3 item 8) the base fixes v_x and v_y: sigma_yy is its reaction, while
  // sigma_xx and sigma_xy are the free face's tractions and stay zero. Deciding by "v_k fixed at
  // the node" alone had left all three free there (and sigma_xy free at a roller/free-top
  // corner); in Case 4(a) that left 2.4x more face-traction residual, 7x worse section
  // equilibrium and 6x more kinetic energy in the steady flow at the toe.
  for (std::size_t i = 0; i < nn; ++i) {
    const std::uint8_t faces = disc_.boundary.faces[i];
    auto& list = per_node[i];
    std::uint8_t reaction = 0;  // stress slots that are reactions at this node
    for (int d = 0; d < Dim; ++d) {
      if ((faces & (3u << (2 * d))) == 0) continue;
      for (int k = 0; k < Dim; ++k) {
        if ((velocity_on_face[i] >> (k * Dim + d)) & 1u) {
          const bool on_k = (faces & (3u << (2 * k))) != 0;
          // A shear sigma_kd shared with a face of normal e_k on which v_d is free is that
          // face's traction and stays zero (the free face wins at the toe corner).
          if (k != d && on_k && !((velocity_on_face[i] >> (d * Dim + k)) & 1u)) continue;
          reaction = static_cast<std::uint8_t>(reaction | (1u << slot<Dim>(k, d)));
        }
      }
    }
    for (int d = 0; d < Dim; ++d) {
      if ((faces & (3u << (2 * d))) == 0) continue;
      for (int k = 0; k < Dim; ++k) {
        const int comp = Dim + slot<Dim>(k, d);
        auto it = std::find_if(list.begin(), list.end(),
                               [&](const NodalConstraint& c) { return c.component == comp; });
        if ((reaction >> slot<Dim>(k, d)) & 1u) {
          if (it != list.end()) list.erase(it);
        } else if (it == list.end()) {
          list.push_back({comp, 0.0, -1});
        }
      }
    }
  }

  constraint_row_.assign(nn + 1, 0);
  diff_row_of_node_.assign(nn, -1);
  std::vector<Index>& constrained = constrained_nodes_;
  constrained.clear();
  for (std::size_t i = 0; i < nn; ++i) {
    std::sort(per_node[i].begin(), per_node[i].end(),
              [](const auto& a, const auto& b) { return a.component < b.component; });
    for (const auto& c : per_node[i]) constraints_.push_back(c);
    constraint_row_[i + 1] = static_cast<Index>(constraints_.size());
    if (!per_node[i].empty()) {
      diff_row_of_node_[i] = static_cast<Index>(constrained.size());
      constrained.push_back(static_cast<Index>(i));
    }
    if (disc_.boundary.faces[i] != 0) boundary_nodes_.push_back(static_cast<Index>(i));
  }
  diff_ne_ = build_difference_gradient<Dim>(disc_.nodes.position, constrained, disc_.elements,
                                            kernel_);
}

template <int Dim>
void StaggeredSolver<Dim>::set_initial_state() {
  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  const int vertical = Dim - 1;  // the last axis points up
  const double g = setup_.gravity.norm();
  double surface = -std::numeric_limits<double>::infinity();
  for (const auto& x : disc_.nodes.position) surface = std::max(surface, x[vertical]);
  if (setup_.surface_level) surface = *setup_.surface_level;
  for (std::size_t i = 0; i < nn; ++i) {
    double* phi = &node_phi_[i * NV];
    for (int d = 0; d < Dim; ++d) phi[d] = setup_.initial_velocity[d];
    const auto m = static_cast<std::size_t>(disc_.nodes.material[i]);
    if (setup_.initial_stress == InitialStressKind::geostatic) {
      // METHOD.md §4.2 option A: sigma_v = -rho g (H - z), lateral = K0 sigma_v.
      const double nu = materials_[m]->elastic().nu;
      const double k0 = setup_.k0.value_or(nu / (1.0 - nu));
      const double sv = -disc_.nodes.density[i] * g * (surface - disc_.nodes.position[i][vertical]);
      for (int n = 0; n < 3; ++n) phi[Dim + n] = (n == vertical ? 1.0 : k0) * sv;
    } else if (setup_.initial_stress == InitialStressKind::uniform) {
      from_sym6<Dim>(setup_.uniform_stress, phi + Dim);
    }
    if (state_stride_ > 0) {
      materials_[m]->initial_state(to_sym6<Dim>(phi + Dim),
                                   &node_state_[i * static_cast<std::size_t>(state_stride_)]);
    }
  }
  apply_constraints(0.0);
  initial_strain_ = energy().strain;
  last_power_ = boundary_power();
  double momentum[Dim] = {};
  double mv2 = 0.0;
  for (std::size_t i = 0; i < nn; ++i) {
    const double m = disc_.nodes.mass(static_cast<Index>(i));
    for (int d = 0; d < Dim; ++d) {
      momentum[d] += m * node_phi_[i * NV + static_cast<std::size_t>(d)];
      mv2 += m * node_phi_[i * NV + static_cast<std::size_t>(d)] * node_phi_[i * NV + static_cast<std::size_t>(d)];
    }
  }
  const double fb = setup_.function_value(setup_.gravity_function, 0.0);
  for (int d = 0; d < Dim; ++d) last_power_ += fb * setup_.gravity[d] * momentum[d];
  last_damping_power_ = damping_at(0.0) * mv2;
  kinetic_peak_ = 0.5 * mv2;
}

template <int Dim>
void StaggeredSolver<Dim>::apply_constraints(double t) {
  // Only the few constrained nodes, not the whole set: this runs two or three times a step.
  for (const Index i : constrained_nodes_) {
    for (Index k = constraint_row_[static_cast<std::size_t>(i)]; k < constraint_row_[static_cast<std::size_t>(i) + 1]; ++k) {
      const NodalConstraint& c = constraints_[static_cast<std::size_t>(k)];
      node_phi_[static_cast<std::size_t>(i) * NV + static_cast<std::size_t>(c.component)] =
          constraint_value(static_cast<std::size_t>(i), c, t);  // V3: sigma' = sigma + p_w
    }
  }
}

template <int Dim>
void StaggeredSolver<Dim>::integrate_sources(double tau, bool on_elements) {
  const auto& runs = on_elements ? elem_runs_ : node_runs_;
  std::vector<double>& phi = on_elements ? elem_phi_ : node_phi_;
  std::vector<double>& state = on_elements ? elem_state_ : node_state_;
  long max_sub = max_substeps_;
#pragma omp parallel for schedule(dynamic) reduction(max : max_sub) if (runs.size() > 4)
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto [m, begin, end] = runs[r];
    const auto b0 = static_cast<std::size_t>(begin);
    SourceBatch batch;
    batch.count = static_cast<std::size_t>(end - begin);
    batch.stress_components = NS;
    batch.sigma_start = &src_sigma_start_[b0 * NS];
    batch.sigma_start_stride = NS;
    batch.flux_rate = &src_rate_[b0 * NS];
    batch.flux_rate_stride = NS;
    batch.sigma_end = &phi[b0 * NV + Dim];
    batch.sigma_end_stride = NV;
    batch.state_start = state.data() + b0 * static_cast<std::size_t>(state_stride_);
    batch.state_end = state.data() + b0 * static_cast<std::size_t>(state_stride_);
    batch.state_stride = static_cast<std::size_t>(state_stride_);
    batch.coupling = setup_.coupling;
    const SourceStats stats = materials_[static_cast<std::size_t>(m)]->advance_source(tau, batch);
    max_sub = std::max(max_sub, stats.max_substeps);
  }
  max_substeps_ = max_sub;
}

// Step 1 (METHOD.md §5.1): nodes -> elements, t^n -> t^{n+1/2}.
template <int Dim>
void StaggeredSolver<Dim>::step_elements(double t) {
  const double tau = 0.5 * dt_;
  const double fb = setup_.function_value(setup_.gravity_function, t + 0.5 * tau);
  double b[Dim];
  for (int d = 0; d < Dim; ++d) b[d] = fb * setup_.gravity[d];
  const double cd = damping_at(t);
  const Index ne = disc_.elements.size();
  // Shared row patterns (operators/corrected_operator.hpp): pair k of element e has the source
  // base[e] + off[k]; on a lattice the few patterns' weights stay in the L1 cache.
  const Index* base = op_en_.base.data();
  const Index* pat = op_en_.pattern.data();
  const Index* pstart = op_en_.pattern_start.data();
  const Index* off = op_en_.offset.data();
  const double* wi = op_en_.interp.data();
  const auto* wg = op_en_.grad.data();
  const double* nphi = node_phi_.data();
  const int stride = state_stride_;
  constexpr std::size_t kRunLen = CorrectedOperator<Dim>::kMaxRun * NV;
  const Index* runs = op_en_.run_start.data();
  const Index nruns = op_en_.runs();
#pragma omp parallel for schedule(static) if (ne > kParallelMin)
  for (Index r = 0; r < nruns; ++r) {
    // Interpolated state (slot 0) and its gradient (slots 1..Dim) of the run's elements.
    double acc[Dim + 1][kRunLen];
    const Index e0 = runs[r], e1 = runs[r + 1];
    const Index k0 = pstart[pat[e0]], k1 = pstart[pat[e0] + 1];
    interpolate_run<Dim, NV>(op_en_, nphi, r, acc);
    for (Index e = e0; e < e1; ++e) {
      const auto slot0 = static_cast<std::size_t>(e - e0) * NV;
      double bar[NV];
      double grad[Dim][NV];
      for (int c = 0; c < NV; ++c) {
        bar[c] = acc[0][slot0 + static_cast<std::size_t>(c)];
        for (int d = 0; d < Dim; ++d) grad[d][c] = acc[1 + d][slot0 + static_cast<std::size_t>(c)];
      }
      const auto eu = static_cast<std::size_t>(e);
      const auto m = static_cast<std::size_t>(disc_.elements.material[eu]);
      double dv[Dim], dsig[NS];
      flux_rates<Dim>(grad, 1.0 / disc_.elements.density[eu], lambda_[m], shear_[m], dv, dsig);
      if (saturated_) {  // V3 (METHOD.md §5.3): -grad p^n / rho in the element half-step
        if (!elem_v_skeleton_.empty()) {  // solver.pressure_divergence = "stress_points"
          for (int i = 0; i < Dim; ++i) {
            elem_v_skeleton_[eu * Dim + static_cast<std::size_t>(i)] = damped_velocity(bar[i], dv[i] + b[i], cd, tau);
          }
        }
        for (Index k = k0; k < k1; ++k) {
          const double pr = pw_[static_cast<std::size_t>(base[e] + off[k])] / disc_.elements.density[eu];
          for (int d = 0; d < Dim; ++d) dv[d] -= wg[k][static_cast<std::size_t>(d)] * pr;
        }
      }
      double* out = &elem_phi_[eu * NV];
      for (int i = 0; i < Dim; ++i) out[i] = damped_velocity(bar[i], dv[i] + b[i], cd, tau);
      for (int s = 0; s < NS; ++s) out[Dim + s] = bar[Dim + s] + tau * dsig[s];
      if (any_source_) {
        for (int s = 0; s < NS; ++s) {
          src_sigma_start_[eu * NS + static_cast<std::size_t>(s)] = bar[Dim + s];
          src_rate_[eu * NS + static_cast<std::size_t>(s)] = dsig[s];
        }
      }
      if (stride > 0) {
        // History variables are interpolated from the nodes (METHOD.md §3.3: nodes are primary).
        double* ks = &elem_state_[eu * static_cast<std::size_t>(stride)];
        for (int j = 0; j < stride; ++j) ks[j] = 0.0;
        for (Index k = k0; k < k1; ++k) {
          const double* kn = &node_state_[static_cast<std::size_t>(base[e] + off[k]) * static_cast<std::size_t>(stride)];
          for (int j = 0; j < stride; ++j) ks[j] += wi[k] * kn[j];
        }
      }
    }
  }
  if (any_source_) integrate_sources(tau, true);
}

// Step 2 (METHOD.md §5.1): elements -> nodes, t^n -> t^{n+1}.
template <int Dim>
void StaggeredSolver<Dim>::step_nodes(double t) {
  const double fb = setup_.function_value(setup_.gravity_function, t + 0.5 * dt_);
  double b[Dim];
  for (int d = 0; d < Dim; ++d) b[d] = fb * setup_.gravity[d];
  const double cd = damping_at(t);
  const double t_half = t + 0.5 * dt_;
  const Index nn = disc_.nodes.size();
  const double* ephi = elem_phi_.data();
  constexpr std::size_t kRunLen = CorrectedOperator<Dim>::kMaxRun * NV;
  const Index* runs = op_ne_.run_start.data();
  const Index nruns = op_ne_.runs();
#pragma omp parallel for schedule(static) if (nn > kParallelMin)
  for (Index r = 0; r < nruns; ++r) {
    // Interpolation (slot 0: the velocity for the displacement) and gradient of the stress
    // points' state at the run's nodes.
    double acc[Dim + 1][kRunLen];
    const Index i0 = runs[r], i1 = runs[r + 1];
    interpolate_run<Dim, NV>(op_ne_, ephi, r, acc);
    for (Index i = i0; i < i1; ++i) {
      const auto slot = static_cast<std::size_t>(i - i0) * NV;
      double grad[Dim][NV];
      for (int c = 0; c < NV; ++c) {
        for (int d = 0; d < Dim; ++d) grad[d][c] = acc[1 + d][slot + static_cast<std::size_t>(c)];
      }
      const auto iu = static_cast<std::size_t>(i);
      // The material velocity at t^{n+1/2} for the displacement: the stress points' velocity,
      // interpolated back. Not the nodal v, which in a steady state keeps an O(dt) component the
      // stress points never see (it balances the filter against the residual nodal force: see
      // docs/method-notes.md, "Displacements"), and would make u drift.
      for (int d = 0; d < Dim; ++d) v_half_[iu * Dim + static_cast<std::size_t>(d)] = acc[0][slot + static_cast<std::size_t>(d)];
      for (Index q = constraint_row_[iu]; q < constraint_row_[iu + 1]; ++q) {
        const NodalConstraint& con = constraints_[static_cast<std::size_t>(q)];
        if (con.component < Dim) v_half_[iu * Dim + static_cast<std::size_t>(con.component)] = constraint_value(iu, con, t_half);
      }
      const Index drow = diff_row_of_node_[iu];
      if (drow >= 0) {
        // METHOD.md §0.3 fix (a): a prescribed component enters its own gradient through the
        // difference form with fhat = the prescribed value at t^{n+1/2}.
        const auto dr = static_cast<std::size_t>(drow);
        for (Index q = constraint_row_[iu]; q < constraint_row_[iu + 1]; ++q) {
          const NodalConstraint& con = constraints_[static_cast<std::size_t>(q)];
          const double fhat = constraint_value(iu, con, t_half);
          double g[Dim] = {};
          for (Index k = diff_ne_.row_start[dr]; k < diff_ne_.row_start[dr + 1]; ++k) {
            const double f = ephi[static_cast<std::size_t>(diff_ne_.source[static_cast<std::size_t>(k)]) * NV +
                                  static_cast<std::size_t>(con.component)];
            for (int d = 0; d < Dim; ++d) g[d] += diff_ne_.weight[static_cast<std::size_t>(k)][d] * f;
          }
          for (int d = 0; d < Dim; ++d) grad[d][con.component] = g[d] - diff_ne_.weight_sum[dr][d] * fhat;
        }
      }
      const auto m = static_cast<std::size_t>(disc_.nodes.material[iu]);
      double dv[Dim], dsig[NS];
      flux_rates<Dim>(grad, 1.0 / disc_.nodes.density[iu], lambda_[m], shear_[m], dv, dsig);
      double* phi = &node_phi_[iu * NV];
      for (int d = 0; d < Dim; ++d) phi[d] = damped_velocity(phi[d], dv[d] + b[d], cd, dt_);
      if (any_source_) {
        for (int s = 0; s < NS; ++s) {
          src_sigma_start_[iu * NS + static_cast<std::size_t>(s)] = phi[Dim + s];
          src_rate_[iu * NS + static_cast<std::size_t>(s)] = dsig[s];
        }
      }
      for (int s = 0; s < NS; ++s) phi[Dim + s] += dt_ * dsig[s];
    }
  }
  if (any_source_) integrate_sources(dt_, false);
}

// Velocity-only fourth-order filter v <- v - eps (I - P_NE P_EN)^2 v (METHOD.md §0.3 item 3):
// removes the nodal checkerboard that the elements cannot see; exact on linear fields.
template <int Dim>
void StaggeredSolver<Dim>::filter_velocity() {
  const Index ne = disc_.elements.size();
  const Index nn = disc_.nodes.size();
  const double eps = setup_.filter_strength;
  auto to_elements = [&](const double* node_field, std::size_t node_stride) {
    // By runs (run_sums): all node_stride components of the run's sources are summed, of which
    // the first Dim are kept; the vector loop is still cheaper than a per-row gather.
    const Index* runs = op_en_.run_start.data();
    const Index nruns = op_en_.runs();
#pragma omp parallel for schedule(static) if (ne > kParallelMin)
    for (Index r = 0; r < nruns; ++r) {
      double acc[CorrectedOperator<Dim>::kMaxRun * NV];
      double* sums[1] = {acc};
      const Index e0 = runs[r], e1 = runs[r + 1];
      const auto e0u = static_cast<std::size_t>(e0);
      const auto p = static_cast<std::size_t>(op_en_.pattern[e0u]);
      run_sums<1, 16>(node_field + static_cast<std::size_t>(op_en_.base[e0u]) * node_stride, node_stride,
                      static_cast<std::size_t>(e1 - e0) * node_stride, op_en_.offset.data(), op_en_.pattern_start[p],
                      op_en_.pattern_start[p + 1], [&](Index k, double* w) { w[0] = op_en_.interp[static_cast<std::size_t>(k)]; },
                      sums);
      for (Index e = e0; e < e1; ++e) {
        for (int d = 0; d < Dim; ++d) {
          filter_elem_[static_cast<std::size_t>(e) * Dim + static_cast<std::size_t>(d)] =
              acc[static_cast<std::size_t>(e - e0) * node_stride + static_cast<std::size_t>(d)];
        }
      }
    }
  };
  auto back_to_nodes = [&](Index i, double* acc) {
    for (int d = 0; d < Dim; ++d) acc[d] = 0.0;
    const auto r = op_ne_.row(i);
    const double* row_field = &filter_elem_[static_cast<std::size_t>(r.base) * Dim];
    for (Index k = r.begin; k < r.end; ++k) {
      const double wk = op_ne_.interp[static_cast<std::size_t>(k)];
      const double* p = row_field + static_cast<std::size_t>(op_ne_.offset[static_cast<std::size_t>(k)]) * Dim;
      for (int d = 0; d < Dim; ++d) acc[d] += wk * p[d];
    }
  };
  to_elements(node_phi_.data(), NV);
#pragma omp parallel for schedule(static) if (nn > kParallelMin)
  for (Index i = 0; i < nn; ++i) {
    double acc[Dim];
    back_to_nodes(i, acc);
    for (int d = 0; d < Dim; ++d) {
      filter_node_[static_cast<std::size_t>(i) * Dim + static_cast<std::size_t>(d)] =
          node_phi_[static_cast<std::size_t>(i) * NV + static_cast<std::size_t>(d)] - acc[d];
    }
  }
  to_elements(filter_node_.data(), Dim);
#pragma omp parallel for schedule(static) if (nn > kParallelMin)
  for (Index i = 0; i < nn; ++i) {
    double acc[Dim];
    back_to_nodes(i, acc);
    for (int d = 0; d < Dim; ++d) {
      const std::size_t k = static_cast<std::size_t>(i) * Dim + static_cast<std::size_t>(d);
      node_phi_[static_cast<std::size_t>(i) * NV + static_cast<std::size_t>(d)] -= eps * (filter_node_[k] - acc[d]);
    }
  }
}

template <int Dim>
double StaggeredSolver<Dim>::boundary_power() const {
  // Power of the surface tractions: sum over face nodes of A (sigma . n) . v.
  double power = 0.0;
  for (Index i : boundary_nodes_) {
    const auto iu = static_cast<std::size_t>(i);
    const double* phi = &node_phi_[iu * NV];
    const std::uint8_t faces = disc_.boundary.faces[iu];
    for (int d = 0; d < Dim; ++d) {
      for (int side = 0; side < 2; ++side) {
        if (((faces >> (2 * d + side)) & 1u) == 0) continue;
        const double normal = side == 0 ? -1.0 : 1.0;
        const double area = disc_.boundary.area[iu][static_cast<std::size_t>(2 * d + side)];
        for (int k = 0; k < Dim; ++k) {
          // V3: the traction is the total stress sigma' - p_w 1.
          const double sk = phi[Dim + slot<Dim>(k, d)] - (saturated_ && k == d ? pw_[iu] : 0.0);
          power += area * sk * normal * phi[k];
        }
      }
    }
  }
  return power;
}

template <int Dim>
void StaggeredSolver<Dim>::finish_step() {
  const Index nn = disc_.nodes.size();
  const Index blocks = (nn + kReductionBlock - 1) / kReductionBlock;
  constexpr int kSums = Dim + 2;  // momentum (Dim), sum m v^2, non-finite flag
#pragma omp parallel for schedule(static) if (nn > kParallelMin)
  for (Index blk = 0; blk < blocks; ++blk) {
    double sums[kSums] = {};
    const Index end = std::min(nn, (blk + 1) * kReductionBlock);
    for (Index i = blk * kReductionBlock; i < end; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      const double m = disc_.nodes.volume[iu] * disc_.nodes.density[iu];
      for (int d = 0; d < Dim; ++d) {
        const double v = node_phi_[iu * NV + static_cast<std::size_t>(d)];
        node_u_[iu * Dim + static_cast<std::size_t>(d)] += dt_ * v_half_[iu * Dim + static_cast<std::size_t>(d)];
        sums[d] += m * v;
        sums[Dim] += m * v * v;
        if (!std::isfinite(v)) sums[Dim + 1] = 1.0;
      }
    }
    for (int s = 0; s < kSums; ++s) block_sums_[static_cast<std::size_t>(blk) * kSums + static_cast<std::size_t>(s)] = sums[s];
  }
  double total[kSums] = {};
  for (Index blk = 0; blk < blocks; ++blk) {
    for (int s = 0; s < kSums; ++s) total[s] += block_sums_[static_cast<std::size_t>(blk) * kSums + static_cast<std::size_t>(s)];
  }
  if (total[Dim + 1] != 0.0) {
    Index bad = 0;
    for (Index i = 0; i < nn; ++i) {
      bool finite = true;
      for (int c = 0; c < NV; ++c) finite = finite && std::isfinite(node_phi_[static_cast<std::size_t>(i) * NV + static_cast<std::size_t>(c)]);
      if (!finite) {
        bad = i;
        break;
      }
    }
    const auto& x = disc_.nodes.position[static_cast<std::size_t>(bad)];
    throw SolverError(fmt::format(
        "the solution became non-finite at step {} (t = {:.6g} s), first at node {} (x = [{}]); "
        "the run is unstable: reduce the time step (time.cfl = {:.3g}) or check the loads and "
        "material parameters",
        steps_ + 1, time_ + dt_, bad, fmt::join(x.data(), x.data() + Dim, ", "), cfl_));
  }
  const double t_new = time_ + dt_;
  const double fb = setup_.function_value(setup_.gravity_function, t_new);
  double power = boundary_power();
  for (int d = 0; d < Dim; ++d) power += fb * setup_.gravity[d] * total[d];
  // Damping switched off once the kinetic energy has decayed (METHOD.md §4.2 option B).
  const double kinetic = 0.5 * total[Dim];
  kinetic_peak_ = std::max(kinetic_peak_, kinetic);
  // It must stay below the ratio for damping.kinetic_ratio_hold (an oscillation trough alone,
  // with the energy momentarily in strain, must not end the relaxation).
  if (setup_.damping_until_kinetic_ratio > 0.0 && t_new >= setup_.damping_ratio_from && t_new < damping_off_time_) {
    if (kinetic < setup_.damping_until_kinetic_ratio * kinetic_peak_) {
      if (kinetic_below_since_ < 0.0) kinetic_below_since_ = t_new;
      if (t_new - kinetic_below_since_ >= setup_.damping_ratio_hold) damping_off_time_ = t_new;
    } else {
      kinetic_below_since_ = -1.0;
    }
  }
  const double cd = damping_at(t_new);
  const double damping_power = cd * total[Dim];
  external_work_ += 0.5 * dt_ * (last_power_ + power);
  damping_loss_ += 0.5 * dt_ * (last_damping_power_ + damping_power);
  // Growth guard: the kinetic energy of a stable run cannot exceed the work done on the body
  // plus its initial energy (the materials only dissipate). An unstable mode grows v^2 faster
  // than the boundary power (~ v) feeds the work, so it trips this long before the values
  // overflow; the factor leaves room for the scheme's own energy error.
  const double budget = std::abs(external_work_) + initial_energy_;
  if (kinetic > kEnergyGrowthLimit * budget && steps_ > 0) {
    throw SolverError(fmt::format(
        "the kinetic energy ({:.3g} J) exceeds {:g} times the work done on the body plus its initial energy "
        "({:.3g} J) at step {} (t = {:.6g} s): the run is unstable; reduce the time step (time.cfl = {:.3g}) or check "
        "the loads, the boundary conditions and the solver options{}",
        kinetic, kEnergyGrowthLimit, budget, steps_ + 1, t_new, cfl_,
        saturated_ && impermeable_stress_faces_ > 0 && undrained_courant_ > kUndrainedCourantLimit
            ? fmt::format(" (V3: impermeable faces carrying a total stress are unstable above C c_u/c_d = {}; "
                          "here it is {:.2f}: time.cfl <= {:.3f})",
                          kUndrainedCourantLimit, undrained_courant_, cfl_ * kUndrainedCourantLimit / undrained_courant_)
            : std::string()));
  }
  last_power_ = power;
  last_damping_power_ = damping_power;
}

template <int Dim>
void StaggeredSolver<Dim>::step() {
  const double t = time_;
  if (steps_ == 0) {
    // The energy the body starts the run with, for the growth guard of finish_step (taken here,
    // not at construction, so that a state set by the caller counts).
    const EnergyBalance e0 = energy();
    initial_energy_ = e0.kinetic + std::abs(e0.strain);
  }
  step_elements(t);
  step_nodes(t);
  apply_constraints(t + dt_);
  if (saturated_) {  // V3: pressure solve and velocity correction (METHOD.md §2.4 steps 2-3)
    pressure_step(t + dt_);
    apply_constraints(t + dt_);
  }
  if (setup_.filter) {
    filter_velocity();
    apply_constraints(t + dt_);
  }
  finish_step();
  time_ = t + dt_;
  ++steps_;
}

template <int Dim>
EnergyBalance StaggeredSolver<Dim>::energy() const {
  EnergyBalance e;
  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  for (std::size_t i = 0; i < nn; ++i) {
    const double* phi = &node_phi_[i * NV];
    const double m = disc_.nodes.mass(static_cast<Index>(i));
    for (int d = 0; d < Dim; ++d) e.kinetic += 0.5 * m * phi[d] * phi[d];
    const Sym6 s = to_sym6<Dim>(phi + Dim);
    const Sym6 eps = materials_[static_cast<std::size_t>(disc_.nodes.material[i])]->elastic().apply_inverse(s);
    double w = 0.0;
    for (std::size_t c = 0; c < 3; ++c) w += s[c] * eps[c];
    for (std::size_t c = 3; c < 6; ++c) w += 2.0 * s[c] * eps[c];
    if (saturated_) w += inv_storage_ * pw_[i] * pw_[i];  // V3: fluid storage p^2/(2Q*)
    e.strain += 0.5 * disc_.nodes.volume[i] * w;
  }
  e.external_work = external_work_;
  e.damping_loss = damping_loss_;
  e.initial_strain = initial_strain_;
  return e;
}

template <int Dim>
std::size_t StaggeredSolver<Dim>::state_bytes() const {
  const std::size_t doubles = node_phi_.size() + elem_phi_.size() + node_u_.size() +
                              node_state_.size() + elem_state_.size() + v_half_.size() +
                              filter_elem_.size() + filter_node_.size();
  std::size_t bytes = doubles * sizeof(double);
  bytes += (disc_.nodes.position.size() + disc_.elements.position.size()) * sizeof(Vec<Dim>);
  bytes += (disc_.nodes.volume.size() + disc_.elements.volume.size()) * 2 * sizeof(double);
  bytes += (disc_.nodes.material.size() + disc_.elements.material.size()) * sizeof(int);
  return bytes;
}

template <int Dim>
std::size_t StaggeredSolver<Dim>::operator_bytes() const {
  return op_en_.bytes() + op_ne_.bytes() + diff_ne_.source.size() * (sizeof(Index) + sizeof(Vec<Dim>)) +
         constraint_row_.size() * sizeof(Index) + constraints_.size() * sizeof(NodalConstraint) +
         diff_row_of_node_.size() * sizeof(Index);
}

template <int Dim>
std::size_t StaggeredSolver<Dim>::step_traffic_bytes() const {
  // A model of the compulsory traffic of step() for V1 with the default velocity filter (the
  // gathers are assumed to hit the cache after a particle's first use, which lattice order
  // gives): per pass, the arrays it reads plus those it writes, reads and writes counted apart.
  const auto nn = static_cast<std::size_t>(disc_.nodes.size());
  const auto ne = static_cast<std::size_t>(disc_.elements.size());
  constexpr std::size_t phi = NV * sizeof(double), vec = Dim * sizeof(double);
  const std::size_t props = sizeof(double) + sizeof(int);  // density, material
  const std::size_t hist = static_cast<std::size_t>(state_stride_) * sizeof(double);
  const std::size_t src = any_source_ ? 2 * NS * sizeof(double) : 0;  // sigma_start, rate
  const std::size_t row_en = op_en_.bytes() - op_en_.interp.size() * sizeof(double) - op_en_.grad.size() * sizeof(op_en_.grad[0]);
  const std::size_t row_ne = op_ne_.bytes() - op_ne_.interp.size() * sizeof(double) - op_ne_.grad.size() * sizeof(op_ne_.grad[0]);
  std::size_t bytes = 0;
  // step_elements: phi_N, history_N -> phi_E, history_E (+ source inputs)
  bytes += nn * (phi + hist) + ne * (phi + hist + props + src) + row_en;
  // step_nodes: phi_E, phi_N -> phi_N, v_prev (+ source inputs)
  bytes += ne * phi + nn * (2 * phi + vec + props + sizeof(Index) + src) + row_ne;
  if (setup_.filter) {
    bytes += nn * phi + ne * vec + row_en;              // P_EN v
    bytes += ne * vec + nn * (phi + vec) + row_ne;      // v - P_NE P_EN v
    bytes += nn * vec + ne * vec + row_en;              // P_EN of that
    bytes += ne * vec + nn * (vec + 2 * phi) + row_ne;  // v -= eps (...)
  }
  // finish_step: volume, density, v, u, v_prev -> u
  bytes += nn * (2 * sizeof(double) + phi + 2 * vec + vec);
  return bytes;
}

template class StaggeredSolver<1>;
template class StaggeredSolver<2>;

}  // namespace rktsph
