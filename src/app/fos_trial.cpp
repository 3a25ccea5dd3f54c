#include "app/fos_trial.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "app/signals.hpp"
#include "core/error.hpp"
#include "io/field_catalogue.hpp"
#include "io/vtu_writer.hpp"
#include "schemes/simulation.hpp"

namespace rktsph::fos {

namespace {

using Clock = std::chrono::steady_clock;

// The node nearest the monitor's position (resolve_monitor checked that it is on the body).
template <int Dim>
Index nearest_node(const ParticleSet<Dim>& nodes, const std::vector<double>& position) {
  Vec<Dim> target;
  for (int d = 0; d < Dim; ++d) target[d] = position[static_cast<std::size_t>(d)];
  Index best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < nodes.size(); ++i) {
    const double distance = (nodes.position[static_cast<std::size_t>(i)] - target).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best = i;
    }
  }
  return best;
}

template <int Dim>
void write_frame(const Simulation<Dim>& solver, const std::filesystem::path& file) {
  const io::FieldCatalogue<Dim> fields(solver, io::FieldCatalogue<Dim>::Set::nodes);
  const auto& x = solver.nodes().position;
  std::vector<double> points(x.size() * 3, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int d = 0; d < Dim; ++d) points[i * 3 + static_cast<std::size_t>(d)] = x[i][d];
  }
  io::write_vtu(file.string(), points, fields.extract());
}

template <int Dim>
TrialResult run(const TrialSpec& spec) {
  const auto t0 = Clock::now();
  TrialResult out;
  const CaseSetup<Dim> setup = read_case<Dim>(*spec.document);
  std::optional<Simulation<Dim>> built;
  try {
    built.emplace(setup);
  } catch (const SolverError& e) {
    out.exit_code = kExitUnstable;
    out.message = e.what();
    return out;
  }
  Simulation<Dim>& solver = *built;
  const Monitor& monitor = spec.monitor;
  Index node = nearest_node(solver.nodes(), monitor.position);
  const std::int64_t node_id = solver.nodes().global_id[static_cast<std::size_t>(node)];
  long reorders = solver.reorders();

  // The end: the hold's, or the case's time.end; the samples as `rktsph run` takes them, so
  // that the load factor's classification reads the same histories as before.
  const double end_time = spec.hold ? spec.hold->end() : setup.end_time;
  const bool adaptive = setup.dt_from_current_state;
  const double dt = solver.clock().initial_dt();
  const long total_steps = static_cast<long>(std::ceil(end_time / dt - 1e-9));
  const double end_tolerance = 1e-12 * end_time;
  auto at_end = [&](long steps) { return adaptive ? solver.time() >= end_time - end_tolerance : steps >= total_steps; };
  const long probe_every = std::max(1, setup.probe_every);
  const long energy_every = std::max(1L, total_steps / 2000);
  // Room for every sample (a step from the current state may be shorter than the first: then
  // samples beyond the room are skipped rather than allocated in the loop).
  TrialHistory& h = out.history;
  const std::size_t probe_room = static_cast<std::size_t>(total_steps / probe_every) + 3;
  const std::size_t energy_room = static_cast<std::size_t>(total_steps / energy_every) + 3;
  h.t.reserve(probe_room);
  h.uc.reserve(probe_room);
  h.energy_t.reserve(energy_room);
  h.kinetic.reserve(energy_room);
  h.kinetic_stress_points.reserve(energy_room);
  h.plastic.reserve(energy_room);

  std::array<double, Dim> direction{};
  for (int d = 0; d < Dim; ++d) direction[static_cast<std::size_t>(d)] = monitor.direction[static_cast<std::size_t>(d)];
  std::optional<HoldCriterion<Dim>> criterion;
  if (spec.hold) criterion.emplace(*spec.hold, std::span<const double, Dim>(direction));

  std::array<double, Dim> u{};
  auto read_monitor = [&] {
    if (solver.reorders() != reorders) {  // V2 sorted its nodes: find the node again by its id
      node = solver.node_with_id(node_id);
      reorders = solver.reorders();
    }
    const auto displacement = solver.node_displacement();
    double uc = 0.0;
    for (int d = 0; d < Dim; ++d) {
      u[static_cast<std::size_t>(d)] = displacement(node, d);
      uc += direction[static_cast<std::size_t>(d)] * u[static_cast<std::size_t>(d)];
    }
    return uc;
  };
  auto record_monitor = [&](double uc) {
    if (h.t.size() == h.t.capacity()) return;
    h.t.push_back(solver.time());
    h.uc.push_back(uc);
  };
  auto record_energy = [&] {
    if (h.energy_t.size() == h.energy_t.capacity()) return;
    const EnergyBalance e = solver.energy();
    h.energy_t.push_back(solver.time());
    h.kinetic.push_back(e.kinetic);
    h.kinetic_stress_points.push_back(e.kinetic_stress_points);
    h.plastic.push_back(e.plastic_dissipation);
  };

  record_monitor(read_monitor());
  record_energy();
  if (criterion) criterion->observe(solver.time(), u);
  try {
    for (long n = 0; !at_end(n); ++n) {
      solver.step();
      const bool last = at_end(n + 1);
      const double uc = read_monitor();
      const bool decided = criterion && criterion->observe(solver.time(), u) != HoldOutcome::running;
      if ((n + 1) % probe_every == 0 || last || decided) record_monitor(uc);
      if ((n + 1) % energy_every == 0 || last || decided) record_energy();
      if (decided) break;  // a collapse seen before the end: nothing later can change it
      if (const int sig = stop_signal(); sig != 0) {
        out.exit_code = 128 + sig;
        out.message = "interrupted";
        break;
      }
    }
  } catch (const SolverError& e) {
    out.exit_code = kExitUnstable;
    out.message = e.what();
  }
  if (criterion) {
    out.hold_outcome = criterion->outcome();
    out.hold = criterion->measures();
  }
  out.steps = solver.step_count();
  out.end_time = solver.time();
  if (!spec.frame.empty() && out.exit_code == 0) write_frame(solver, spec.frame);
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

}  // namespace

TrialResult run_trial(const TrialSpec& spec) {
  omp_set_num_threads(std::max(1, spec.threads));  // this thread's team: trials run side by side
  const int dim = case_dimension(*spec.document);
  if (dim == 1) return run<1>(spec);
  if (dim == 3) return run<3>(spec);
  return run<2>(spec);
}

}  // namespace rktsph::fos
