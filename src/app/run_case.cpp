// `rktsph run`: read a case, build the solver, march in time, write ParaView files, probes,
// energies and a summary (docs/output.md).
#include "app/run_case.hpp"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "io/field_catalogue.hpp"
#include "io/vtu_writer.hpp"
#include "rktsph/version.hpp"
#include "schemes/pressure_stage.hpp"
#include "schemes/simulation.hpp"

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

template <int Dim>
int run_dim(const RunOptions& opt, const CaseDocument& doc) {
  const auto t_setup = Clock::now();
  CaseSetup<Dim> setup = read_case<Dim>(doc);
  const std::string case_name = fs::path(opt.case_file).stem().string();
  const fs::path out = opt.out_dir.empty() ? fs::path("out") / case_name : fs::path(opt.out_dir);
  fs::create_directories(out / "vtu");
  {
    std::ofstream resolved(out / "case.resolved.toml");
    resolved << "# resolved input of " << opt.case_file << " (rktsph " << kVersion << ", " << kGitRevision << ")\n"
             << doc.table << "\n";
  }

  Simulation<Dim> solver(setup);
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - t_setup).count();
  const io::FieldCatalogue<Dim> node_fields(solver, io::FieldCatalogue<Dim>::Set::nodes);
  const io::FieldCatalogue<Dim> stress_point_fields(solver, io::FieldCatalogue<Dim>::Set::stress_points);
  const PorePressureStage<Dim>* pressure = solver.scheme().template find<PorePressureStage<Dim>>();

  // Probes: the nearest node; a probe outside the body is an input error.
  struct Probe {
    std::string name;
    Index node;
    std::vector<std::pair<std::string, io::ScalarField>> fields;
  };
  std::vector<Probe> probes;
  const auto& nodes = solver.nodes();
  for (const ProbeSpec& spec : setup.probes) {
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
    if (best_d > 0.5 * std::sqrt(static_cast<double>(Dim)) * setup.dx + 1e-9) {
      throw InputError(
          fmt::format("{}: probe '{}' at [{}] lies outside the body (nearest node "
                      "is {:.4g} m away)",
                      spec.where, spec.name, fmt::join(spec.position, ", "), best_d));
    }
    Probe p{spec.name, best, {}};
    for (const auto& f : spec.fields) {
      auto value = node_fields.scalar(f);
      if (!value) {
        throw InputError(fmt::format("{}, key 'probe.fields': unknown field '{}' for probe '{}' (available: {})",
                                     spec.where, f, spec.name, fmt::join(node_fields.scalar_names(), ", ")));
      }
      p.fields.emplace_back(f, std::move(*value));
    }
    probes.push_back(std::move(p));
  }

  std::ofstream probe_csv(out / "probes.csv");
  probe_csv << "t";
  for (const auto& p : probes) {
    for (const auto& [fname, ref] : p.fields) probe_csv << "," << p.name << "." << fname;
  }
  probe_csv << "\n";
  auto record_probes = [&] {
    probe_csv << fmt::format("{:.10g}", solver.time());
    for (const auto& p : probes) {
      for (const auto& [fname, value] : p.fields) probe_csv << fmt::format(",{:.10g}", value(p.node));
    }
    probe_csv << "\n";
  };

  std::ofstream energy_csv(out / "energy.csv");
  energy_csv << "t,kinetic,strain,external_work,damping_loss,imbalance\n";
  auto record_energy = [&] {
    const EnergyBalance e = solver.energy();
    energy_csv << fmt::format("{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}\n", solver.time(), e.kinetic,
                              e.strain - e.initial_strain, e.external_work, e.damping_loss, e.imbalance());
  };

  io::PvdCollection node_pvd((out / "nodes.pvd").string());
  io::PvdCollection elem_pvd((out / "elements.pvd").string());
  int frame = 0;
  const auto node_points = padded_points<Dim>(solver.nodes().position);
  const auto elem_points = padded_points<Dim>(solver.stress_points().position);
  auto write_frame = [&] {
    const std::string name = fmt::format("nodes_{:06d}.vtu", frame);  // NOLINT
    io::write_vtu((out / "vtu" / name).string(), node_points, node_fields.extract());
    node_pvd.add(solver.time(), "vtu/" + name);
    if (setup.output_elements) {
      const std::string ename = fmt::format("elements_{:06d}.vtu", frame);
      io::write_vtu((out / "vtu" / ename).string(), elem_points, stress_point_fields.extract());
      elem_pvd.add(solver.time(), "vtu/" + ename);
    }
    ++frame;
  };

  const double dt = solver.dt();
  const long total_steps = static_cast<long>(std::ceil(setup.end_time / dt - 1e-9));
  const long energy_every = std::max(1L, total_steps / 2000);
  const bool progress = !opt.quiet && isatty(fileno(stderr)) != 0;
  if (!opt.quiet) {
    std::cerr << fmt::format(
        "rktsph {}: {} ({}D, {} nodes, {} stress points, dt = {:.4g} s, C = {:.3f}, {} steps, "
        "{} thread{})\n",
        kVersion, opt.case_file, Dim, solver.nodes().size(), solver.stress_points().size(), dt, solver.cfl(),
        total_steps, omp_get_max_threads(), omp_get_max_threads() > 1 ? "s" : "");
    if (pressure != nullptr && pressure->impermeable_stress_face_nodes() > 0 &&
        pressure->undrained_courant() > PorePressureStage<Dim>::kUndrainedCourantLimit) {
      std::cerr << fmt::format(
          "warning: {} boundary nodes are on impermeable faces that carry a total stress (or are free), and the "
          "undrained Courant number C c_u/c_d = {:.2f} exceeds {}, above which such faces have been measured "
          "unstable; time.cfl <= {:.3f} keeps it below (docs/VALIDATION.md, Case 16)\n",
          pressure->impermeable_stress_face_nodes(), pressure->undrained_courant(),
          PorePressureStage<Dim>::kUndrainedCourantLimit,
          solver.cfl() * PorePressureStage<Dim>::kUndrainedCourantLimit / pressure->undrained_courant());
    }
    if (solver.degenerate_operator_rows() > 0) {
      std::cerr << fmt::format(
          "warning: {} particles have too few neighbours for the corrected "
          "operator and use plain SPH sums\n",
          solver.degenerate_operator_rows());
    }
  }

  record_probes();
  record_energy();
  write_frame();
  double next_output = setup.output_interval > 0 ? setup.output_interval : std::numeric_limits<double>::infinity();
  std::size_t next_time_index = 0;
  while (next_time_index < setup.output_times.size() && setup.output_times[next_time_index] <= 0.0) ++next_time_index;

  std::string status = "completed", message;
  int exit_code = 0;
  const auto t_loop = Clock::now();
  auto last_progress = t_loop;
  try {
    for (long n = 0; n < total_steps; ++n) {
      solver.step();
      const bool last = n + 1 == total_steps;
      if ((n + 1) % setup.probe_every == 0 || last) record_probes();
      if ((n + 1) % energy_every == 0 || last) record_energy();
      bool output = last;
      const double t = solver.time();
      if (t >= next_output - 1e-12 * setup.end_time) {
        output = true;
        while (next_output <= t + 1e-12 * setup.end_time) next_output += setup.output_interval;
      }
      // Snapshots requested at given times: the first step at or after each time.
      while (next_time_index < setup.output_times.size() && t >= setup.output_times[next_time_index] - 1e-12) {
        output = true;
        ++next_time_index;
      }
      if (output) write_frame();
      if (progress) {
        const auto now = Clock::now();
        if (std::chrono::duration<double>(now - last_progress).count() > 0.5 || last) {
          last_progress = now;
          const double elapsed = std::chrono::duration<double>(now - t_loop).count();
          const double eta = elapsed * static_cast<double>(total_steps - n - 1) / static_cast<double>(n + 1);
          std::cerr << fmt::format("\r  t = {:.5g} s of {:.5g} s ({:3.0f} %), step {} of {}, ETA {}   ", t,
                                   setup.end_time, 100.0 * t / setup.end_time, n + 1, total_steps, duration_text(eta))
                    << std::flush;
        }
      }
    }
    if (progress) std::cerr << "\n";
  } catch (const SolverError& e) {
    if (progress) std::cerr << "\n";
    status = "unstable";
    message = e.what();
    exit_code = 3;
  }
  const double loop_seconds = std::chrono::duration<double>(Clock::now() - t_loop).count();
  probe_csv.flush();
  energy_csv.flush();

  const double nodes_count = static_cast<double>(solver.nodes().size());
  const double node_steps = nodes_count * static_cast<double>(solver.step_count());
  const int threads = omp_get_max_threads();
  const EnergyBalance e = solver.energy();
  nlohmann::json summary = {
      {"case", opt.case_file},
      {"title", setup.title},
      {"status", status},
      {"message", message},
      {"version", kVersion},
      {"git_revision", kGitRevision},
      {"dimension", Dim},
      {"nodes", solver.nodes().size()},
      {"stress_points", solver.stress_points().size()},
      {"spacing", setup.dx},
      {"smoothing_length", setup.h_over_dx * setup.dx},
      {"max_wave_speed", solver.max_wave_speed()},
      {"dt", dt},
      {"cfl", solver.cfl()},
      {"steps", solver.step_count()},
      {"time", solver.time()},
      {"threads", threads},
      {"setup_seconds", setup_seconds},
      {"wall_seconds", loop_seconds},
      {"node_steps_per_second", loop_seconds > 0 ? node_steps / loop_seconds : 0.0},
      {"node_steps_per_second_per_thread", loop_seconds > 0 ? node_steps / loop_seconds / threads : 0.0},
      {"neighbour_pairs", solver.pairs()},
      {"pairs_per_node", static_cast<double>(solver.pairs()) / nodes_count},
      {"bytes_state", solver.state_bytes()},
      {"bytes_operators", solver.operator_bytes()},
      {"bytes_per_node", static_cast<double>(solver.state_bytes() + solver.operator_bytes()) / nodes_count},
      {"max_source_substeps", solver.max_source_substeps()},
      {"energy",
       {{"kinetic", e.kinetic},
        {"strain", e.strain - e.initial_strain},
        {"external_work", e.external_work},
        {"damping_loss", e.damping_loss},
        {"imbalance", e.imbalance()}}},
      {"output_frames", frame},
  };
  // Damping switched off by the kinetic-energy test (damping.until_kinetic_ratio), or null.
  summary["damping_off_time"] = std::isfinite(solver.clock().damping_off_time())
                                    ? nlohmann::json(solver.clock().damping_off_time())
                                    : nlohmann::json(nullptr);
  summary["peak_kinetic_energy"] = solver.clock().peak_kinetic_energy();
  if (pressure != nullptr) {
    const PressureSolveStats* ps = &pressure->stats();
    // V3: the pore-pressure solve (method-notes §2.4): PCG iterations, residual, time share.
    summary["pressure_solve"] = {
        {"preconditioner", setup.fluid.incomplete_cholesky ? "incomplete_cholesky" : "jacobi"},
        {"tolerance", setup.fluid.tolerance},
        {"unknowns", pressure->solver().unknowns()},
        {"solves", ps->solves},
        {"iterations_max", ps->max_iterations},
        {"iterations_mean", ps->mean_iterations()},
        {"final_residual", ps->last_error},
        {"max_residual", ps->max_error},
        {"solve_seconds", ps->seconds},
        {"pressure_step_seconds", pressure->seconds()},
        {"share_of_loop_time", loop_seconds > 0 ? pressure->seconds() / loop_seconds : 0.0},
    };
  }
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";
  if (!opt.quiet) {
    if (pressure != nullptr) {
      const PressureSolveStats* ps = &pressure->stats();
      std::cerr << fmt::format(
          "pore pressure: {} PCG solves, iterations mean {:.1f} / max {}, final relative "
          "residual {:.2e}; pressure step {:.0f} % of the loop time\n",
          ps->solves, ps->mean_iterations(), ps->max_iterations, ps->last_error,
          loop_seconds > 0 ? 100.0 * pressure->seconds() / loop_seconds : 0.0);
    }
    if (exit_code == 0) {
      std::cerr << fmt::format("done: {} steps in {:.2f} s ({:.3g} node-steps/s); output in {}\n", solver.step_count(),
                               loop_seconds, loop_seconds > 0 ? node_steps / loop_seconds : 0.0, out.string());
    } else {
      std::cerr << fmt::format("error: {}\nthe output up to the last good step is kept in {}\n", message, out.string());
    }
  }
  return exit_code;
}

}  // namespace

int run_case(const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const CaseDocument doc = load_case_document(opt.case_file, opt.overrides);
  const int dim = case_dimension(doc);
  if (dim == 1) return run_dim<1>(opt, doc);
  return run_dim<2>(opt, doc);
}

}  // namespace rktsph
