#include "app/run_loop.hpp"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "app/signals.hpp"
#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "io/field_catalogue.hpp"
#include "io/output_files.hpp"
#include "io/runout.hpp"
#include "io/vtu_writer.hpp"
#include "rktsph/version.hpp"
#include "schemes/deactivate_stage.hpp"
#include "schemes/pressure_stage.hpp"
#include "schemes/reseed_stage.hpp"
#include "schemes/shift_stage.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

template <int Dim>
std::vector<double> padded_points(const std::vector<Vec<Dim>>& x) {
  std::vector<double> pts(x.size() * 3, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int d = 0; d < Dim; ++d) pts[i * 3 + static_cast<std::size_t>(d)] = x[i][d];
  }
  return pts;
}

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 90) return fmt::format("{:.0f} s", seconds);
  if (seconds < 5400) return fmt::format("{:.1f} min", seconds / 60);
  return fmt::format("{:.1f} h", seconds / 3600);
}

// The pvd entries as two archive values (times; names joined by newlines), and back.
void save_entries(io::StateArchive& a, const std::string& key, const std::vector<io::PvdCollection::Entry>& e) {
  std::vector<double> times;
  std::string names;
  for (const auto& [t, f] : e) {
    times.push_back(t);
    names += f + "\n";
  }
  a.put(key + "/times", times);
  a.put_text(key + "/files", names);
}

std::vector<io::PvdCollection::Entry> load_entries(const io::StateArchive& a, const std::string& key) {
  const auto& times = a.doubles(key + "/times");
  std::istringstream names(a.text(key + "/files"));
  std::vector<io::PvdCollection::Entry> out;
  std::string line;
  for (double t : times) {
    if (!std::getline(names, line)) throw InputError("the checkpoint's list of frames is damaged");
    out.emplace_back(t, line);
  }
  return out;
}

// Everything the loop needs to continue its output streams exactly.
struct LoopState {
  long frame = 0;
  double next_output = 0.0;
  long next_time_index = 0;
  long energy_every = 1;
  double next_checkpoint = 0.0;  // simulated time of the next periodic checkpoint
  long checkpoints = 0;
  double loop_seconds = 0.0;  // time-loop wall time of the earlier segments of the run
  long resumed_from = -1;     // step a resumed run started from (-1: not resumed)
};

}  // namespace

template <int Dim>
Index probe_node(const ProbeSpec& spec, const ParticleSet<Dim>& nodes, double dx) {
  Vec<Dim> x;
  for (int d = 0; d < Dim; ++d) x[d] = spec.position[static_cast<std::size_t>(d)];
  Index best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < nodes.size(); ++i) {
    const double dist = (nodes.position[static_cast<std::size_t>(i)] - x).norm();
    if (dist < best_d) {
      best_d = dist;
      best = i;
    }
  }
  if (best_d > 0.5 * std::sqrt(static_cast<double>(Dim)) * dx + 1e-9) {
    throw InputError(fmt::format("{}: probe '{}' at [{}] lies outside the body (nearest node is {:.4g} m away)",
                                 spec.where, spec.name, fmt::join(spec.position, ", "), best_d));
  }
  return best;
}

template <int Dim>
io::ScalarField probe_field(const ProbeSpec& spec, const std::string& field, const io::FieldCatalogue<Dim>& nodes) {
  auto value = nodes.scalar(field);
  if (!value) {
    throw InputError(fmt::format("{}: unknown field '{}' for probe '{}' (available: {})",
                                 spec.fields_where.empty() ? spec.where : spec.fields_where, field, spec.name,
                                 fmt::join(nodes.scalar_names(), ", ")));
  }
  return std::move(*value);
}

template <int Dim>
int run_loop(const LoopInput& in) {
  const RunOptions& opt = in.options;
  const fs::path& out = in.out;
  const bool resuming = in.checkpoint != nullptr;
  const auto t_setup = Clock::now();
  const CaseSetup<Dim> setup = read_case<Dim>(in.document);
  Simulation<Dim> solver(setup);
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - t_setup).count();
  const io::FieldCatalogue<Dim> node_fields(solver, io::FieldCatalogue<Dim>::Set::nodes);
  // Remade when V2 re-seeds its stress points (the catalogue reads the set's arrays).
  std::optional<io::FieldCatalogue<Dim>> stress_point_fields;
  std::int64_t stress_point_fields_made = -1;
  const PorePressureStage<Dim>* pressure = solver.scheme().template find<PorePressureStage<Dim>>();

  // Probes: the node nearest the position in the initial configuration; outside the body, an input error.
  struct Probe {
    std::string name;
    Index node;
    std::int64_t id;  // the node's global id: V2 reorders its nodes, the probe follows the id
    std::vector<std::pair<std::string, io::ScalarField>> fields;
  };
  std::vector<Probe> probes;
  const auto& nodes = solver.nodes();
  for (const ProbeSpec& spec : setup.probes) {
    const Index best = probe_node(spec, nodes, setup.dx);
    Probe p{spec.name, best, nodes.global_id[static_cast<std::size_t>(best)], {}};
    for (const auto& f : spec.fields) p.fields.emplace_back(f, probe_field(spec, f, node_fields));
    probes.push_back(std::move(p));
  }
  // After the probes: a probe follows the node nearest its position as the case made the nodes,
  // which in large deformation have moved by the time of a checkpoint.
  if (resuming) solver.load_state(*in.checkpoint);

  // The steps of a fixed step; with the step from the current state (time.dt_rule = "current",
  // method-notes eq. (4.3.3)) the run ends on the clock and this is the initial step's estimate.
  const bool adaptive = setup.dt_from_current_state;
  const double dt = solver.clock().initial_dt();
  const long total_steps = static_cast<long>(std::ceil(setup.end_time / dt - 1e-9));
  const double end_tolerance = 1e-12 * setup.end_time;
  auto at_end = [&](long steps) {
    return adaptive ? solver.time() >= setup.end_time - end_tolerance : steps >= total_steps;
  };
  const double checkpoint_every = setup.checkpoint_interval.value_or(setup.end_time / 10.0);
  LoopState loop;
  if (resuming && (adaptive ? solver.time() > setup.end_time + end_tolerance : solver.step_count() > total_steps)) {
    throw InputError(fmt::format("{}: the checkpoint is at t = {:.6g} s (step {}), past time.end = {:.6g} s",
                                 out.string(), solver.time(), solver.step_count(), setup.end_time));
  }
  if (resuming && at_end(solver.step_count())) {
    if (!opt.quiet) {
      std::cerr << fmt::format("{}: the run is complete (t = {:.6g} s); extend it with --set time.end=...\n",
                               out.string(), solver.time());
    }
    return 0;
  }
  if (resuming) {
    const io::StateArchive& a = *in.checkpoint;
    loop.frame = static_cast<long>(a.integer("run/frame"));
    loop.next_output = a.number("run/next_output");
    loop.next_time_index = static_cast<long>(a.integer("run/next_time_index"));
    loop.energy_every = static_cast<long>(a.integer("run/energy_every"));
    loop.checkpoints = static_cast<long>(a.integer("run/checkpoints"));
    loop.loop_seconds = a.number("run/loop_seconds");
    loop.resumed_from = solver.step_count();
    loop.next_checkpoint = a.number("run/next_checkpoint");
    if (setup.checkpoint_interval && *setup.checkpoint_interval != a.number("run/checkpoint_interval")) {
      loop.next_checkpoint = checkpoint_every > 0.0 ? solver.time() + checkpoint_every : HUGE_VAL;  // changed on resume
    }
    // Frames written after the checkpoint (up to the interruption) are replaced as the run goes.
    for (const auto& entry : fs::directory_iterator(out / "vtu")) {
      const std::string f = entry.path().filename().string();
      long index = -1;
      if (std::sscanf(f.c_str(), "nodes_%ld.vtu", &index) == 1 ||
          std::sscanf(f.c_str(), "elements_%ld.vtu", &index) == 1) {
        if (index >= loop.frame) fs::remove(entry.path());
      }
    }
  } else {
    loop.energy_every = std::max(1L, total_steps / 2000);
    loop.next_output = setup.output_interval > 0 ? setup.output_interval : std::numeric_limits<double>::infinity();
    while (loop.next_time_index < static_cast<long>(setup.output_times.size()) &&
           setup.output_times[static_cast<std::size_t>(loop.next_time_index)] <= 0.0) {
      ++loop.next_time_index;
    }
    loop.next_checkpoint = checkpoint_every > 0.0 ? checkpoint_every : HUGE_VAL;
  }

  // Output streams: a fresh run starts them; a resumed one cuts them back to the checkpoint.
  io::RowFile probe_csv((out / "probes.csv").string(), resuming ? in.checkpoint->integer("run/probes_bytes") : -1);
  io::RowFile energy_csv((out / "energy.csv").string(), resuming ? in.checkpoint->integer("run/energy_bytes") : -1);
  // bodies.csv (rigid bodies, V1/V2/V3): one row per body at every output step.
  const BodyOutput* bodies = nullptr;
  for (const auto& stage : solver.scheme().stages()) {
    if (auto* c = dynamic_cast<const BodyOutput*>(stage.get())) bodies = c;
  }
  std::optional<io::RowFile> bodies_csv;
  if (bodies != nullptr) {
    bodies_csv.emplace((out / "bodies.csv").string(), resuming ? in.checkpoint->integer("run/bodies_bytes") : -1);
    if (!resuming) bodies_csv->append(body_csv_header());
  }
  // contact.csv (V2's contact): the contact pressure profile of every body at every output step.
  std::optional<io::RowFile> contact_csv;
  if (bodies != nullptr && bodies->has_contact_profile()) {
    // A checkpoint of a build without the file restarts it (-1: an empty file and its header).
    const bool kept = resuming && in.checkpoint->has("run/contact_bytes");
    contact_csv.emplace((out / "contact.csv").string(), kept ? in.checkpoint->integer("run/contact_bytes") : -1);
    if (!kept) contact_csv->append(contact_csv_header());
  }
  // runout.csv and deposit.csv (V2 in 2D with rigid bodies, docs/output.md "Run-out measures"):
  // the deposit's front, heights, particle disorder and mass at every output step, and the
  // surface profile of the latest one. The base and the first column are the lowest and the
  // leftmost reference positions (x - u), so a resumed run finds them as a fresh one did.
  std::optional<io::RowFile> runout_csv;
  double runout_x0 = 0.0, runout_base = 0.0;
  if (bodies != nullptr && setup.version == "v2") {
    // A checkpoint of a build without the file restarts it (-1: an empty file and its header).
    const bool kept = resuming && in.checkpoint->has("run/runout_bytes");
    runout_csv.emplace((out / "runout.csv").string(), kept ? in.checkpoint->integer("run/runout_bytes") : -1);
    if (!kept) {
      runout_csv->append(
          "t,front,first_column_height,max_height,detached,surface_nodes,nn_min,nn_mean,nn_max,nn_cv,clustered,"
          "isolated,mass\n");
    }
    const auto u = solver.node_displacement();
    runout_x0 = runout_base = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < solver.nodes().size(); ++i) {
      runout_x0 = std::min(runout_x0, solver.nodes().position[static_cast<std::size_t>(i)][0] - u(i, 0));
      if constexpr (Dim >= 2) {
        runout_base = std::min(runout_base, solver.nodes().position[static_cast<std::size_t>(i)][1] - u(i, 1));
      }
    }
  }
  // What runout.csv and particles.csv share, measured once per output step (2D).
  struct NodeMeasures {
    io::Disorder disorder;
    long surface = 0;  // flagged free-surface nodes
    double mass = 0.0;
  };
  auto measure_nodes = [&] {
    NodeMeasures m;
    if constexpr (Dim == 2) {
      const auto& set = solver.nodes();
      m.disorder = io::particle_disorder(set.position, setup.dx);
      if (const auto f = set.template find<double, 1>("free_surface"); f.valid()) {
        for (Index i = 0; i < set.size(); ++i) m.surface += set.view(f)(i, 0) != 0.0 ? 1 : 0;
      }
      m.mass = solver.total_mass();
    }
    return m;
  };
  auto record_runout = [&](const NodeMeasures& m) {
    if constexpr (Dim == 2) {
      if (!runout_csv) return;
      const auto& set = solver.nodes();
      const double dx = setup.dx;
      double xmax = runout_x0, hmax = 0.0;
      for (const auto& p : set.position) xmax = std::max(xmax, p[0]), hmax = std::max(hmax, p[1] - runout_base);
      const io::DepositProfile p = io::deposit_profile(set.position, runout_x0, xmax + dx, dx, runout_base);
      const io::Disorder& d = m.disorder;
      runout_csv->append(fmt::format(
          "{:.10g},{:.10g},{:.10g},{:.10g},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{},{},{:.15g}\n", solver.time(), p.front,
          p.h.front(), hmax, p.detached, m.surface, d.min, d.mean, d.max, d.cv, d.clustered, d.isolated, m.mass));
      std::string profile =
          fmt::format("# t = {:.10g} s; h above the base y = {:.10g} m\nx,h,count\n", solver.time(), runout_base);
      for (std::size_t k = 0; k < p.h.size(); ++k) {
        profile += fmt::format("{:.10g},{:.10g},{}\n", p.centre(k), p.h[k], p.count[k]);
      }
      io::write_file_atomically((out / "deposit.csv").string(), profile, false);
    }
  };
  // particles.csv (V2 in 2D, docs/output.md): the particle disorder of the nodes, the mass and
  // the regularisations (issue 12 item 5) at every output step, with or without bodies.
  std::optional<io::RowFile> particles_csv;
  const ReseedStressPoints<Dim>* reseed_stage = solver.scheme().template find<ReseedStressPoints<Dim>>();
  const ShiftNodes<Dim>* shift_stage = nullptr;
  if constexpr (Dim >= 2) shift_stage = solver.scheme().template find<ShiftNodes<Dim>>();
  const DeactivateOutside<Dim>* deactivate_stage = solver.scheme().template find<DeactivateOutside<Dim>>();
  if (Dim == 2 && setup.version == "v2") {
    const std::string header =
        "t,nn_min,nn_mean,nn_max,nn_cv,clustered,isolated,surface_nodes,mass,stress_points,reseeds,shifts,"
        "deactivated,deactivated_mass";
    // A checkpoint of a build without the file, or whose file has other columns (an earlier
    // build's), restarts it: rows of two layouts in one table would be misread.
    bool kept = resuming && in.checkpoint->has("run/particles_bytes");
    if (kept) {
      std::ifstream existing(out / "particles.csv");
      std::string first;
      kept = std::getline(existing, first) && first == header;
    }
    particles_csv.emplace((out / "particles.csv").string(), kept ? in.checkpoint->integer("run/particles_bytes") : -1);
    if (!kept) particles_csv->append(header + "\n");
  }
  auto record_particles = [&](const NodeMeasures& m) {
    if (!particles_csv) return;
    const io::Disorder& d = m.disorder;
    particles_csv->append(fmt::format(
        "{:.10g},{:.6g},{:.6g},{:.6g},{:.6g},{},{},{},{:.15g},{},{},{},{},{:.15g}\n", solver.time(), d.min, d.mean,
        d.max, d.cv, d.clustered, d.isolated, m.surface, m.mass, solver.stress_points().size(),
        reseed_stage != nullptr ? reseed_stage->reseeds() : 0L, shift_stage != nullptr ? shift_stage->shifts() : 0L,
        deactivate_stage != nullptr ? deactivate_stage->deactivated() : 0L,
        deactivate_stage != nullptr ? deactivate_stage->deactivated_mass() : 0.0));
  };
  auto record_bodies = [&] {
    if (bodies_csv) bodies_csv->append(bodies->csv_rows(solver.time()));
    if (contact_csv) contact_csv->append(bodies->contact_rows(solver.time()));
    if (runout_csv || particles_csv) {
      const NodeMeasures m = measure_nodes();
      record_runout(m);
      record_particles(m);
    }
  };
  io::PvdCollection node_pvd((out / "nodes.pvd").string());
  io::PvdCollection elem_pvd((out / "elements.pvd").string());
  if (resuming) {
    node_pvd.restore(load_entries(*in.checkpoint, "run/node_frames"));
    elem_pvd.restore(load_entries(*in.checkpoint, "run/stress_point_frames"));
  } else {
    std::string header = "t";
    for (const auto& p : probes) {
      for (const auto& [fname, ref] : p.fields) header += fmt::format(",{}.{}", p.name, fname);
    }
    probe_csv.append(header + "\n");
    energy_csv.append(
        "t,kinetic,strain,external_work,damping_loss,imbalance,kinetic_stress_points,plastic_dissipation,"
        "stabilisation_loss\n");
  }
  long probes_reorders = 0;
  auto record_probes = [&] {
    if (solver.reorders() != probes_reorders) {
      // The nodes were reordered (sorted by cell): find each probe's node again by its id.
      for (auto& p : probes) p.node = solver.node_with_id(p.id);
      probes_reorders = solver.reorders();
    }
    std::string row = fmt::format("{:.10g}", solver.time());
    for (const auto& p : probes) {
      for (const auto& [fname, value] : p.fields) row += fmt::format(",{:.10g}", value(p.node));
    }
    probe_csv.append(row + "\n");
  };
  auto record_energy = [&] {
    const EnergyBalance e = solver.energy();
    // A stress can overflow while every velocity is still finite (the step's own check looks at
    // the velocities): an infinite energy is an unstable run, never a completed one.
    if (!std::isfinite(e.kinetic + e.strain + e.external_work + e.damping_loss)) {
      throw SolverError(
          fmt::format("the energy became non-finite at t = {:.6g} s (step {}): the run is unstable; "
                      "reduce the time step (time.cfl = {:.3g}) or check the loads and material parameters",
                      solver.time(), solver.step_count(), solver.cfl()));
    }
    energy_csv.append(fmt::format("{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}\n",
                                  solver.time(), e.kinetic, e.strain - e.initial_strain, e.external_work,
                                  e.damping_loss, e.imbalance(), e.kinetic_stress_points, e.plastic_dissipation,
                                  e.stabilisation_loss));
  };
  auto write_frame = [&] {
    // The current positions (they move in a large-deformation scheme).
    const auto node_points = padded_points<Dim>(solver.nodes().position);
    const std::string name = fmt::format("nodes_{:06d}.vtu", loop.frame);
    io::write_vtu((out / "vtu" / name).string(), node_points, node_fields.extract());
    node_pvd.add(solver.time(), "vtu/" + name);
    if (setup.output_elements) {
      const std::string ename = fmt::format("elements_{:06d}.vtu", loop.frame);
      if (stress_point_fields_made != solver.stress_points().replacements()) {
        stress_point_fields.emplace(solver, io::FieldCatalogue<Dim>::Set::stress_points);
        stress_point_fields_made = solver.stress_points().replacements();
      }
      io::write_vtu((out / "vtu" / ename).string(), padded_points<Dim>(solver.stress_points().position),
                    stress_point_fields->extract());
      elem_pvd.add(solver.time(), "vtu/" + ename);
    }
    ++loop.frame;
  };
  auto flush_streams = [&] {
    probe_csv.flush();
    energy_csv.flush();
    if (bodies_csv) bodies_csv->flush();
    if (contact_csv) contact_csv->flush();
    if (runout_csv) runout_csv->flush();
    if (particles_csv) particles_csv->flush();
  };
  const fs::path checkpoint_file = out / "checkpoint" / "checkpoint.h5";
  auto write_checkpoint = [&](double loop_seconds) {
    flush_streams();
    io::StateArchive a;
    solver.save_state(a);
    a.put_text("case/document", [&] {
      std::ostringstream text;
      text << in.document.table;
      return text.str();
    }());
    a.put_text("case/file", opt.case_file);
    a.put_integer("case/dimension", Dim);
    a.put_integer("run/frame", loop.frame);
    a.put("run/next_output", loop.next_output);
    a.put_integer("run/next_time_index", loop.next_time_index);
    a.put_integer("run/energy_every", loop.energy_every);
    a.put_integer("run/checkpoints", loop.checkpoints + 1);
    a.put("run/loop_seconds", loop_seconds);
    a.put("run/next_checkpoint", loop.next_checkpoint);
    a.put("run/checkpoint_interval", checkpoint_every);
    a.put_integer("run/probes_bytes", probe_csv.written());
    a.put_integer("run/energy_bytes", energy_csv.written());
    if (bodies_csv) a.put_integer("run/bodies_bytes", bodies_csv->written());
    if (contact_csv) a.put_integer("run/contact_bytes", contact_csv->written());
    if (runout_csv) a.put_integer("run/runout_bytes", runout_csv->written());
    if (particles_csv) a.put_integer("run/particles_bytes", particles_csv->written());
    save_entries(a, "run/node_frames", node_pvd.entries());
    save_entries(a, "run/stress_point_frames", elem_pvd.entries());
    fs::create_directories(out / "checkpoint");
    io::write_checkpoint(checkpoint_file.string(), a);
    ++loop.checkpoints;
  };

  // summary.json: written at the start (status "running") and replaced at the end.
  const int threads = omp_get_max_threads();
  const char* omp_wait = std::getenv("OMP_WAIT_POLICY");  // set to passive by main unless the user chose
  const std::string wait_policy = omp_wait != nullptr ? omp_wait : "runtime default";
  auto summary = [&](const std::string& status, const std::string& message, double loop_seconds) {
    const double nodes_count = static_cast<double>(solver.nodes().size());
    const double segment_steps = static_cast<double>(solver.step_count() - std::max(0L, loop.resumed_from));
    const double node_steps = nodes_count * segment_steps;
    const double segment_seconds = loop_seconds - loop.loop_seconds;
    const EnergyBalance e = solver.energy();
    nlohmann::json j = {
        {"case", opt.case_file},
        {"title", setup.title},
        {"status", status},
        {"message", message},
        {"version", kVersion},
        {"git_revision", kGitRevision},
        {"dimension", Dim},
        {"scheme", solver.scheme().name()},
        {"nodes", solver.nodes().size()},
        {"stress_points", solver.stress_points().size()},
        {"spacing", setup.dx},
        {"smoothing_length", setup.smoothing_length()},
        {"max_wave_speed", solver.max_wave_speed()},
        {"dt", solver.dt()},
        {"dt_rule", adaptive ? "current" : "fixed"},
        {"dt_initial", dt},
        {"dt_min", solver.clock().dt_min()},
        {"dt_max", solver.clock().dt_max()},
        {"cfl", solver.cfl()},
        {"steps", solver.step_count()},
        {"steps_planned", total_steps},
        {"time", solver.time()},
        {"threads", threads},
        {"omp_wait_policy", wait_policy},
        {"threads_adaptive", exec::adaptive_teams()},  // and the share of those loops' calls run on all threads:
        {"team_call_share",
         static_cast<double>(exec::team_stats().team_calls) /
             static_cast<double>(std::max(1L, exec::team_stats().team_calls + exec::team_stats().single_calls))},
        {"setup_seconds", setup_seconds},
        {"wall_seconds", loop_seconds},
        {"node_steps_per_second", segment_seconds > 0 ? node_steps / segment_seconds : 0.0},
        {"node_steps_per_second_per_thread", segment_seconds > 0 ? node_steps / segment_seconds / threads : 0.0},
        {"neighbour_pairs", solver.pairs()},
        {"pairs_per_node", static_cast<double>(solver.pairs()) / nodes_count},
        {"bytes_state", solver.state_bytes()},
        {"bytes_operators", solver.operator_bytes()},
        {"bytes_per_node", static_cast<double>(solver.state_bytes() + solver.operator_bytes()) / nodes_count},
        {"max_source_substeps", solver.max_source_substeps()},
        {"source",
         {{"elastic_points", solver.source_stats().elastic_points},
          {"rk4_points", solver.source_stats().rk4_points},
          {"rk4_substeps", solver.source_stats().total_substeps},
          {"max_rk4_substeps", solver.source_stats().max_substeps},
          {"implicit_points", solver.source_stats().implicit_points},
          {"newton_iterations", solver.source_stats().newton_iterations},
          {"max_newton_iterations", solver.source_stats().max_newton_iterations},
          {"max_implicit_pieces", solver.source_stats().max_implicit_pieces},
          {"seconds", solver.source_seconds()}}},
        {"energy",
         {{"kinetic", e.kinetic},
          {"strain", e.strain - e.initial_strain},
          {"external_work", e.external_work},
          {"damping_loss", e.damping_loss},
          {"plastic_dissipation", e.plastic_dissipation},
          {"stabilisation_loss", e.stabilisation_loss},
          {"imbalance", e.imbalance()}}},
        {"output_frames", loop.frame},
        {"checkpoints_written", loop.checkpoints},
    };
    j["checkpoint"] = loop.checkpoints > 0 ? nlohmann::json(checkpoint_file.string()) : nlohmann::json(nullptr);
    j["resumed_from_step"] = loop.resumed_from >= 0 ? nlohmann::json(loop.resumed_from) : nlohmann::json(nullptr);
    j["damping_off_time"] = std::isfinite(solver.clock().damping_off_time())
                                ? nlohmann::json(solver.clock().damping_off_time())
                                : nlohmann::json(nullptr);
    j["peak_kinetic_energy"] = solver.clock().peak_kinetic_energy();
    for (const auto& stage : solver.scheme().stages()) {
      for (const auto& [key, value] : stage->report()) j["stages"][std::string(stage->name())][key] = value;
    }
    if (pressure != nullptr) {
      // V3: the pore-pressure solve (method-notes §2.4): PCG iterations, residual, time share.
      const PressureSolveStats& ps = pressure->stats();
      j["pressure_solve"] = {
          {"preconditioner", pressure->implicit_faces()        ? "jacobi"
                             : setup.fluid.incomplete_cholesky ? "incomplete_cholesky"
                                                               : "jacobi"},
          {"method", pressure->implicit_faces() ? "bicgstab" : "conjugate_gradient"},
          {"storage_rate", setup.fluid.storage_rate == FluidSpec::StorageRate::consistent ? "consistent"
                           : setup.fluid.storage_rate == FluidSpec::StorageRate::nodes ? "nodes"
                                                                                       : "stress_points"},
          {"implicit_face_nodes", pressure->implicit_faces() ? pressure->impermeable_stress_face_nodes() : 0},
          {"undrained_courant", pressure->undrained_courant()},
          {"filter_quadratic_fit_nodes", pressure->filter_fitted_rows()},
          {"tolerance", setup.fluid.tolerance},
          {"unknowns", pressure->solver().unknowns()},
          {"solves", ps.solves},
          {"iterations_max", ps.max_iterations},
          {"iterations_mean", ps.mean_iterations()},
          {"final_residual", ps.last_error},
          {"max_residual", ps.max_error},
          {"solve_seconds", ps.seconds},
          {"pressure_step_seconds", pressure->seconds()},
          {"share_of_loop_time", loop_seconds > 0 ? pressure->seconds() / loop_seconds : 0.0},
      };
    }
    io::write_file_atomically((out / "summary.json").string(), j.dump(2) + "\n");
  };

  const bool progress = !opt.quiet && isatty(fileno(stderr)) != 0;
  if (!opt.quiet) {
    if (resuming) {
      std::cerr << fmt::format(
          "rktsph {}: resuming {} at step {} {} (t = {:.6g} s), {} thread{}{}, wait policy {}\n", kVersion,
          out.string(), solver.step_count(),
          adaptive ? fmt::format("(dt = {:.4g} s from the current state)", solver.dt())
                   : fmt::format("of {}", total_steps),
          solver.time(), threads, threads > 1 ? "s" : "", exec::adaptive_teams() ? " (adaptive)" : "", wait_policy);
    } else {
      std::cerr << fmt::format(
          "rktsph {}: {} ({}D, {} nodes, {} stress points, dt = {:.4g} s{}, C = {:.3f}, {} steps{}, {} thread{}{}, "
          "wait policy {})\n",
          kVersion, opt.case_file, Dim, solver.nodes().size(), solver.stress_points().size(), dt,
          adaptive ? " at the start, then from the current state" : "", solver.cfl(), total_steps,
          adaptive ? " if it stays" : "", threads, threads > 1 ? "s" : "", exec::adaptive_teams() ? " (adaptive)" : "",
          wait_policy);
    }
    if (pressure != nullptr && pressure->implicit_faces()) {
      std::cerr << fmt::format(
          "pore pressure: {} nodes of impermeable faces that carry a total stress (or are free) taken "
          "implicitly (undrained Courant number C c_u/c_d = {:.2f}; BiCGSTAB, method-notes §2.4)\n",
          pressure->impermeable_stress_face_nodes(), pressure->undrained_courant());
    }
    if (pressure != nullptr && pressure->impermeable_stress_face_nodes() > 0 && !pressure->implicit_faces() &&
        pressure->undrained_courant() > pressure->undrained_courant_limit()) {
      std::cerr << fmt::format(
          "warning: {} boundary nodes are on impermeable faces that carry a total stress (or are free), and the "
          "undrained Courant number C c_u/c_d = {:.2f} exceeds {}, above which such faces have been measured "
          "unstable; time.cfl <= {:.3f} keeps it below (docs/VALIDATION.md, Case 16)\n",
          pressure->impermeable_stress_face_nodes(), pressure->undrained_courant(),
          pressure->undrained_courant_limit(),
          solver.cfl() * pressure->undrained_courant_limit() / pressure->undrained_courant());
    }
    if (solver.degenerate_operator_rows() > 0) {
      std::cerr << fmt::format(
          "warning: {} particles have too few neighbours for the corrected operator and use "
          "plain SPH sums\n",
          solver.degenerate_operator_rows());
    }
  }

  install_stop_handlers();
  std::string status = "completed", message;
  int exit_code = 0;
  const auto t_loop = Clock::now();
  auto loop_seconds = [&] { return loop.loop_seconds + std::chrono::duration<double>(Clock::now() - t_loop).count(); };
  try {
    summary("running", "", loop.loop_seconds);
    if (!resuming) {
      record_probes();
      record_energy();
      record_bodies();
      write_frame();
      flush_streams();
    }
    auto last_progress = t_loop;
    const long first = solver.step_count();
    const double t_first = solver.time();
    // Moving particles (V2) can lose their neighbours: say so once, when it first happens.
    Index degenerate_seen = solver.degenerate_operator_rows();
    for (long n = first; !at_end(n); ++n) {
      solver.step();
      if (solver.degenerate_operator_rows() > degenerate_seen) {
        degenerate_seen = std::numeric_limits<Index>::max();
        std::cerr << fmt::format(
            "warning: at t = {:.6g} s, {} particles have too few neighbours for the corrected operator and use "
            "plain SPH sums: the body is separating (gaps) or thinning below the kernel's support there\n",
            solver.time(), solver.degenerate_operator_rows());
      }
      const bool last = at_end(n + 1);
      if ((n + 1) % setup.probe_every == 0 || last) record_probes();
      if ((n + 1) % loop.energy_every == 0 || last) record_energy();
      bool output = last;
      const double t = solver.time();
      if (t >= loop.next_output - 1e-12 * setup.end_time) {
        output = true;
        while (loop.next_output <= t + 1e-12 * setup.end_time) loop.next_output += setup.output_interval;
      }
      // Snapshots requested at given times: the first step at or after each time.
      while (loop.next_time_index < static_cast<long>(setup.output_times.size()) &&
             t >= setup.output_times[static_cast<std::size_t>(loop.next_time_index)] - 1e-12) {
        output = true;
        ++loop.next_time_index;
      }
      if (output) {
        record_bodies();
        write_frame();
        flush_streams();  // the tables are on disk at every output step
      }
      if (t >= loop.next_checkpoint - 1e-12 * setup.end_time && !last) {
        while (loop.next_checkpoint <= t + 1e-12 * setup.end_time) loop.next_checkpoint += checkpoint_every;
        write_checkpoint(loop_seconds());
      }
      if (const int sig = stop_signal(); sig != 0 && !last) {
        // Stopped by a signal: a checkpoint of this state, then a frame of it for the user (the
        // checkpoint's list of frames ends before it: a resumed run rewrites it in turn).
        write_checkpoint(loop_seconds());
        if (!output) write_frame();
        status = "interrupted";
        message = fmt::format("stopped by signal {} ({}) after step {} at t = {:.6g} s; resume with: rktsph resume {}",
                              sig, sig == SIGINT ? "SIGINT" : (sig == SIGTERM ? "SIGTERM" : "signal"),
                              solver.step_count(), t, out.string());
        exit_code = 128 + sig;
        break;
      }
      if (progress) {
        const auto now = Clock::now();
        if (std::chrono::duration<double>(now - last_progress).count() > 0.5 || last) {
          last_progress = now;
          const double elapsed = std::chrono::duration<double>(now - t_loop).count();
          const double eta =
              adaptive ? elapsed * (setup.end_time - t) / std::max(t - t_first, 1e-300)
                       : elapsed * static_cast<double>(total_steps - n - 1) / static_cast<double>(n + 1 - first);
          const std::string of_steps = adaptive ? fmt::format("dt = {:.4g} s", solver.dt())
                                                : fmt::format("of {}", total_steps);
          std::cerr << fmt::format("\r  t = {:.5g} s of {:.5g} s ({:3.0f} %), step {} {}, ETA {}   ", t,
                                   setup.end_time, 100.0 * t / setup.end_time, n + 1, of_steps, duration_text(eta))
                    << std::flush;
        }
      }
    }
    if (progress) std::cerr << "\n";
    flush_streams();
    // A checkpoint of the end state: the run can be extended (rktsph resume --set time.end=...).
    if (exit_code == 0 && checkpoint_every > 0.0) write_checkpoint(loop_seconds());
  } catch (const SolverError& e) {
    if (progress) std::cerr << "\n";
    status = "unstable";
    message = e.what();
    exit_code = kExitUnstable;
  } catch (const IoError& e) {
    if (progress) std::cerr << "\n";
    status = "failed";
    message = e.what();
    exit_code = kExitIo;
  }
  if (exit_code == kExitUnstable) {
    try {
      flush_streams();  // the rows of the last good steps
    } catch (const IoError& e) {
      message += fmt::format("; {}", e.what());
    }
  }
  const double seconds = loop_seconds();
  try {
    summary(status, message, seconds);
  } catch (const IoError& e) {
    // The disk is full or gone: say so, and keep the status of the run.
    std::cerr << "error: " << e.what() << "\n";
    if (exit_code == 0) exit_code = kExitIo;
  }
  if (!opt.quiet) {
    if (pressure != nullptr) {
      const PressureSolveStats& ps = pressure->stats();
      std::cerr << fmt::format(
          "pore pressure: {} {} solves, iterations mean {:.1f} / max {}, final relative "
          "residual {:.2e}; pressure step {:.0f} % of the loop time\n",
          ps.solves, pressure->implicit_faces() ? "BiCGSTAB" : "PCG", ps.mean_iterations(), ps.max_iterations,
          ps.last_error, seconds > 0 ? 100.0 * pressure->seconds() / seconds : 0.0);
    }
    // The viscoplastic source: how it was integrated, and its share of the loop (method-notes
    // §2.5); a run whose plastic cost dominates says so.
    if (const SourceStats st = solver.source_stats(); st.total_substeps > 0 || st.implicit_points > 0) {
      const double source_share = seconds > 0 ? 100.0 * solver.source_seconds() / seconds : 0.0;
      std::cerr << fmt::format(
          "viscoplastic source: {} RK4 sub-steps (at most {} a particle), {} backward-Euler returns ({:.1f} Newton "
          "iterations each, at most {}); {:.0f} % of the loop time{}\n",
          st.total_substeps, st.max_substeps, st.implicit_points,
          st.implicit_points > 0 ? static_cast<double>(st.newton_iterations) / static_cast<double>(st.implicit_points)
                                 : 0.0,
          st.max_newton_iterations, source_share,
          source_share > 50.0 ? " (the plastic integration dominates the run)" : "");
    }
    // V2: what rebuilding the neighbours and operators cost, the surface, the domain box.
    auto figure = [](const Stage* stage, const std::string& key) {
      for (const auto& [k, v] : stage->report()) {
        if (k == key) return v;
      }
      return 0.0;
    };
    auto share = [&](double part) { return seconds > 0 ? 100.0 * part / seconds : 0.0; };
    if (const Stage* rebuild = solver.scheme().template find<RebuildOperators<Dim>>(); rebuild != nullptr) {
      std::cerr << fmt::format(
          "neighbours: {:.0f} searches ({:.3g} s, {:.0f} % of the loop); operators rebuilt {:.0f} times ({:.3g} s, "
          "{:.0f} %)\n",
          figure(rebuild, "neighbour_searches"), figure(rebuild, "neighbour_search_seconds"),
          share(figure(rebuild, "neighbour_search_seconds")), figure(rebuild, "operator_builds"),
          figure(rebuild, "operator_build_seconds"), share(figure(rebuild, "operator_build_seconds")));
    }
    if (const Stage* surface = solver.scheme().template find<DetectFreeSurface<Dim>>(); surface != nullptr) {
      std::cerr << fmt::format("free surface: {:.0f} nodes at the last step; detection {:.3g} s ({:.0f} %)\n",
                               figure(surface, "surface_nodes_last_step"), figure(surface, "detection_seconds"),
                               share(figure(surface, "detection_seconds")));
    }
    if (adaptive) {
      std::cerr << fmt::format("time step from the current state: {:.4g} to {:.4g} s (initial {:.4g} s)\n",
                               solver.clock().dt_min(), solver.clock().dt_max(), dt);
    }
    if (deactivate_stage != nullptr && deactivate_stage->deactivated() > 0) {
      std::cerr << fmt::format(
          "domain box: {} particles deactivated (first at t = {:.4g} s), {:.6g} kg (per metre in 2D) of mass\n",
          deactivate_stage->deactivated(), figure(deactivate_stage, "first_deactivation_time"),
          deactivate_stage->deactivated_mass());
    }
    if (reseed_stage != nullptr) {
      std::cerr << fmt::format("stress points re-seeded {} times (first at t = {:.4g} s); {} stress points now\n",
                               reseed_stage->reseeds(), reseed_stage->first_time(), solver.stress_points().size());
    }
    const double node_steps = static_cast<double>(solver.nodes().size()) *
                              static_cast<double>(solver.step_count() - std::max(0L, loop.resumed_from));
    const double segment = seconds - loop.loop_seconds;
    if (exit_code == 0) {
      std::cerr << fmt::format("done: {} steps in {:.2f} s ({:.3g} node-steps/s); output in {}\n",
                               solver.step_count() - std::max(0L, loop.resumed_from), segment,
                               segment > 0 ? node_steps / segment : 0.0, out.string());
    }
  }
  // A run that did not complete says why, --quiet or not.
  if (status == "interrupted") {
    std::cerr << fmt::format("{}\n", message);
  } else if (exit_code != 0) {
    std::cerr << fmt::format("error: {}\nthe output up to the last good step is kept in {}\n", message, out.string());
  }
  return exit_code;
}

template int run_loop<1>(const LoopInput&);
template int run_loop<2>(const LoopInput&);
template int run_loop<3>(const LoopInput&);
template Index probe_node<1>(const ProbeSpec&, const ParticleSet<1>&, double);
template Index probe_node<2>(const ProbeSpec&, const ParticleSet<2>&, double);
template io::ScalarField probe_field<1>(const ProbeSpec&, const std::string&, const io::FieldCatalogue<1>&);
template io::ScalarField probe_field<2>(const ProbeSpec&, const std::string&, const io::FieldCatalogue<2>&);

}  // namespace rktsph
