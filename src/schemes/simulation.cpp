#include "schemes/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"
#include "schemes/registry.hpp"
#include "schemes/staggered_stages.hpp"

namespace rktsph {

template <int Dim>
Simulation<Dim>::Simulation(CaseSetup<Dim> setup, exec::Threads policy)
    : model_(std::make_unique<StaggeredModel<Dim>>(std::move(setup), policy)),
      scheme_(create_scheme<Dim>(model_->setup.version, *model_)),
      clock_(model_->setup, model_->time_step),
      nodes_made_(model_->nodes.fingerprint()),
      stress_points_made_(model_->stress_points.fingerprint()) {
  model_->set_initial_state();
  clock_.start(energy().strain, external_power(), balance_sums());
}

template <int Dim>
double Simulation<Dim>::external_power() {
  return model_->boundary_power() + (scheme_->extra_power ? scheme_->extra_power() : 0.0);
}

template <int Dim>
StepSums<Dim> Simulation<Dim>::balance_sums(double speed_limit2) {
  const ParticleSet<Dim>& nodes = model_->nodes;
  const auto v = nodes.view(model_->fields.velocity);
  return exec::particle_reduce<Dim + 3>(model_->policy, nodes.size(), reduction_, [&](Index i, double* sums) {
    const auto iu = static_cast<std::size_t>(i);
    const double m = nodes.volume[iu] * nodes.density[iu];
    double speed2 = 0.0;
    for (int d = 0; d < Dim; ++d) {
      const double vd = v(i, d);
      sums[d] += m * vd;
      sums[Dim] += m * vd * vd;
      speed2 += vd * vd;
      if (!std::isfinite(vd)) sums[Dim + 1] = 1.0;
    }
    if (speed2 > speed_limit2) sums[Dim + 2] += 1.0;
  });
}

template <int Dim>
double Simulation<Dim>::speed_limit2(double dt) const {
  if (model_->setup.dt) return std::numeric_limits<double>::infinity();
  const double dx = model_->dx();
  return dx * dx / (dt * dt);
}

template <int Dim>
void Simulation<Dim>::step() {
  const double t = clock_.time();
  if (clock_.steps() == 0) {
    const EnergyBalance e0 = energy();
    clock_.set_initial_energy(e0.kinetic + std::abs(e0.strain));
  }
  if (model_->setup.dt_from_current_state) choose_step(t);
  StepContext context;
  context.t = t;
  context.dt = clock_.dt();
  context.damping = clock_.damping_at(t);
  scheme_->run(context);

  const StepSums<Dim> sums = balance_sums(speed_limit2(context.dt));
  if (sums[Dim + 1] != 0.0) {
    const auto v = nodes().view(model_->fields.velocity);
    const auto s = nodes().view(model_->fields.stress);
    Index bad = 0;
    for (Index i = 0; i < nodes().size(); ++i) {
      bool finite = true;
      for (int d = 0; d < Dim; ++d) finite = finite && std::isfinite(v(i, d));
      for (int c = 0; c < kStressComponents<Dim>; ++c) finite = finite && std::isfinite(s(i, c));
      if (!finite) {
        bad = i;
        break;
      }
    }
    const auto& x = nodes().position[static_cast<std::size_t>(bad)];
    throw SolverError(fmt::format(
        "the solution became non-finite at step {} (t = {:.6g} s), first at node {} (x = [{}]); "
        "the run is unstable: reduce the time step (time.cfl = {:.3g}) or check the loads and "
        "material parameters",
        clock_.steps() + 1, t + clock_.dt(), bad, fmt::join(x.data(), x.data() + Dim, ", "), clock_.courant()));
  }
  const double imposed =
      model_->imposed_kinetic() + (scheme_->extra_imposed_kinetic ? scheme_->extra_imposed_kinetic() : 0.0);
  const double dt = clock_.dt();
  clock_.end_step(sums, external_power(), imposed, [this] {
    return (scheme_->instability_hint ? scheme_->instability_hint() : std::string()) + fastest_node();
  });
  check_node_speeds(t, dt, sums[Dim + 2]);
}

// A node that moves more than one particle spacing in a step: the step, set by the wave speed
// (C dx / c), no longer resolves its motion; in a flow this is a node thrown out of the body by
// an instability whose kinetic energy is still too small a part of the work done for the growth
// guard (Case 9 without the stress filter, dx = 0.25 m: stopped here at 7.68 s, the node at
// 396 m/s; the kinetic energy then rose to 7e7 J by 7.73 s, under 100 times the work of gravity,
// and the guard tripped only at 10.1 s). Stopping here keeps the last good output. Only where the wave speed sets the
// step (time.cfl): a step the case fixes (time.dt) may be meant to outrun the waves, as in the
// Jaumann tests' rigid rotation of a body made stiff against its own inertia.
template <int Dim>
void Simulation<Dim>::check_node_speeds(double t, double dt, double fast) {
  if (fast == 0.0) return;
  const double dx = model_->dx();
  throw SolverError(fmt::format(
      "{} node{} moved more than one particle spacing (dx = {:.3g} m) in step {} (t = {:.6g} s): |v| > dx / dt = "
      "{:.3g} m/s, {:.3g} times the fastest wave speed that sets the step; the step no longer resolves their motion "
      "and the run is unstable{}{}",
      static_cast<long>(fast), fast > 1.0 ? "s" : "", dx, clock_.steps(), t + dt, dx / dt,
      dx / dt / clock_.wave_speed(), scheme_->instability_hint ? scheme_->instability_hint() : std::string(),
      fastest_node()));
}

template <int Dim>
std::string Simulation<Dim>::fastest_node() const {
  const ParticleSet<Dim>& nodes = model_->nodes;
  const auto v = nodes.view(model_->fields.velocity);
  Index fastest = -1;
  double speed2 = -1.0;
  for (Index i = 0; i < nodes.size(); ++i) {
    double s2 = 0.0;
    for (int d = 0; d < Dim; ++d) s2 += v(i, d) * v(i, d);
    if (s2 > speed2) speed2 = s2, fastest = i;
  }
  if (fastest < 0) return {};
  const Vec<Dim>& x = nodes.position[static_cast<std::size_t>(fastest)];
  const double support = 2.0 * model_->kernel.h(), dx = model_->dx();
  long near_nodes = 0, near_points = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (Index j = 0; j < nodes.size(); ++j) {
    if (j == fastest) continue;
    const double r = (nodes.position[static_cast<std::size_t>(j)] - x).norm();
    nearest = std::min(nearest, r);
    near_nodes += r < support ? 1 : 0;
  }
  for (const Vec<Dim>& xe : model_->stress_points.position) near_points += (xe - x).norm() < support ? 1 : 0;
  // Where it came from: a node that the growth has thrown clear of the body is named by its place
  // in the body as made (x - u).
  const auto u = nodes.view(model_->fields.displacement);
  Vec<Dim> origin = x;
  for (int d = 0; d < Dim; ++d) origin[d] -= u(fastest, d);
  std::string surface;
  if (const auto f = nodes.template find<double, 1>("free_surface"); f.valid()) {
    surface = nodes.view(f)(fastest, 0) != 0.0 ? ", flagged as free surface" : ", not flagged as free surface";
  }
  return fmt::format(
      ". The fastest node is at x = [{:.4g}] (at [{:.4g}] in the body as made), |v| = {:.3g} m/s{}, with {} stress "
      "points and {} other nodes within its support (2h = {:.3g} m), the nearest node {:.2f} dx away",
      fmt::join(x.data(), x.data() + Dim, ", "), fmt::join(origin.data(), origin.data() + Dim, ", "), std::sqrt(speed2),
      surface, near_points, near_nodes, support, nearest / dx);
}

template <int Dim>
void Simulation<Dim>::choose_step(double t) {
  // eq. (4.3.3): the case's Courant number over the fastest wave of the current state, on the
  // initial spacing (the smoothing length is fixed; method-notes §4.3 says why the particle
  // spacing does not enter), and the last step cut to end on time.end.
  double stretch = 0.0;
  const double c = model_->current_wave_speed(&stretch);
  const double rule_dt = clock_.courant() * model_->dx() / c;
  double dt = rule_dt;
  const double end = model_->setup.end_time;
  if (t + dt >= end - 1e-12 * end) dt = std::max(end - t, 0.0);
  if (rule_dt < kSmallestStepRatio * clock_.initial_dt()) {
    throw SolverError(fmt::format(
        "the time step from the current state fell to {:.3g} s at t = {:.6g} s, {:.2g} of the initial {:.3g} s: a "
        "particle's density is {:.3g} times below its material's (c = {:.4g} m/s); the body is tearing apart",
        rule_dt, t, rule_dt / clock_.initial_dt(), clock_.initial_dt(), stretch, c));
  }
  clock_.set_dt(dt, rule_dt);
}

template <int Dim>
EnergyBalance Simulation<Dim>::energy() const {
  EnergyBalance e;
  const ParticleSet<Dim>& nodes = model_->nodes;
  const auto v = nodes.view(model_->fields.velocity);
  const auto s = nodes.view(model_->fields.stress);
  const auto& stored = scheme_->stored_energy_density;
  for (Index i = 0; i < nodes.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const double m = nodes.mass(i);
    for (int d = 0; d < Dim; ++d) e.kinetic += 0.5 * m * v(i, d) * v(i, d);
    const Sym6 sig = to_sym6<Dim>(s[i]);
    const Sym6 eps = model_->materials[nodes.material[iu]].elastic().apply_inverse(sig);
    double w = 0.0;
    for (std::size_t c = 0; c < 3; ++c) w += sig[c] * eps[c];
    for (std::size_t c = 3; c < 6; ++c) w += 2.0 * sig[c] * eps[c];
    if (stored) w += stored(i);  // V3: fluid storage p^2/(2Q*)
    e.strain += 0.5 * nodes.volume[iu] * w;
  }
  const ParticleSet<Dim>& points = model_->stress_points;
  const auto v_sp = points.view(model_->fields.sp_velocity);
  for (Index k = 0; k < points.size(); ++k) {
    double v2 = 0.0;
    for (int d = 0; d < Dim; ++d) v2 += v_sp(k, d) * v_sp(k, d);
    e.kinetic_stress_points += 0.5 * points.mass(k) * v2;
  }
  e.external_work = clock_.external_work();
  e.damping_loss = clock_.damping_loss();
  e.initial_strain = clock_.initial_strain();
  for (const auto& stage : scheme_->stages()) {
    if (auto* owner = dynamic_cast<const SourceOwner<Dim>*>(stage.get())) {
      e.plastic_dissipation = owner->sources().dissipation();
      e.stabilisation_loss = owner->stabilisation_loss();
    }
  }
  return e;
}

template <int Dim>
std::span<const double> Simulation<Dim>::node_pore_pressure() const {
  if (!saturated()) return {};
  const auto p = nodes().view(model_->fields.pore_pressure);
  return {p.data(), static_cast<std::size_t>(p.size())};
}

template <int Dim>
std::span<double> Simulation<Dim>::mutable_node_pore_pressure() {
  if (!saturated()) return {};
  auto p = model_->nodes.view(model_->fields.pore_pressure);
  return {p.data(), static_cast<std::size_t>(p.size())};
}

template <int Dim>
HistoryView Simulation<Dim>::node_history(std::string_view name) const {
  const int k = history_layout().find(name);
  if (k < 0) throw SolverError(fmt::format("no material of this case has the history variable '{}'", name));
  return HistoryView(nodes().view(model_->fields.history), history_layout(), nodes().material, k);
}

template <int Dim>
HistoryView Simulation<Dim>::stress_point_history(std::string_view name) const {
  const int k = history_layout().find(name);
  if (k < 0) throw SolverError(fmt::format("no material of this case has the history variable '{}'", name));
  return HistoryView(stress_points().view(model_->fields.sp_history), history_layout(), stress_points().material, k);
}

template <int Dim>
SourceStats Simulation<Dim>::source_stats() const {
  // Steps 1 and 2 share one ViscoplasticSources; step 2 of any scheme owns it.
  for (const auto& stage : scheme_->stages()) {
    if (auto* s = dynamic_cast<const SourceOwner<Dim>*>(stage.get())) return s->sources().stats();
  }
  return {};
}

template <int Dim>
double Simulation<Dim>::source_seconds() const {
  for (const auto& stage : scheme_->stages()) {
    if (auto* s = dynamic_cast<const SourceOwner<Dim>*>(stage.get())) return s->sources().seconds();
  }
  return 0.0;
}

template class Simulation<1>;
template class Simulation<2>;
template class Simulation<3>;

}  // namespace rktsph
