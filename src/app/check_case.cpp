#include "app/check_case.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <iostream>
#include <vector>

#include <fmt/format.h>

#include "app/run_loop.hpp"
#include "case/case_reader.hpp"
#include "case/material_point_reader.hpp"
#include "core/error.hpp"
#include "io/field_catalogue.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string duration_text(double s) {
  if (s < 120.0) return fmt::format("{:.3g} s", s);
  if (s < 7200.0) return fmt::format("{:.3g} min", s / 60.0);
  return fmt::format("{:.3g} h", s / 3600.0);
}

// The cost of one backward-Euler return of each Perzyna material (ns), from a batch of trial
// states beyond its surface: the initial stress plus a deviatoric strain of 10 Y/G (a flowing
// particle's trial is much nearer; this bounds it).
template <int Dim>
double plastic_return_ns(const Simulation<Dim>& solver) {
  const auto& m = solver.model();
  double worst = 0.0;
  for (const auto& model : m.materials.models) {
    const Material& mat = *model;
    if (!mat.has_implicit_source()) continue;
    constexpr std::size_t kCount = 512;
    std::vector<double> k0(static_cast<std::size_t>(std::max(1, mat.state_size())), 0.0);
    const Sym6 sigma0{-1.0e5, -1.0e5, -1.0e5, 0.0, 0.0, 0.0};
    mat.initial_state(sigma0, k0.data());
    const double G = mat.elastic().G;
    std::vector<double> start(kCount * 6), end(kCount * 6), kin(kCount * k0.size()), kout(kCount * k0.size());
    for (std::size_t i = 0; i < kCount; ++i) {
      // Shear of varied size and direction, 10 Y/G of the reference yield stress 1e5 Pa at most.
      const double g = 10.0 * 1.0e5 / G * (0.2 + 0.8 * static_cast<double>(i % 17) / 16.0);
      const Sym6 e{0.3 * g, -0.3 * g, 0.0, g, 0.0, 0.0};
      const Sym6 d = mat.elastic().apply(e);
      for (std::size_t c = 0; c < 6; ++c) start[i * 6 + c] = sigma0[c] + d[c];
      for (std::size_t j = 0; j < k0.size(); ++j) kin[i * k0.size() + j] = k0[j];
    }
    SourceBatch b;
    b.count = kCount;
    b.stress_components = 6;
    b.sigma_start = start.data();
    b.sigma_start_stride = 6;
    b.sigma_end = end.data();
    b.sigma_end_stride = 6;
    b.state_start = kin.data();
    b.state_end = kout.data();
    b.state_stride = k0.size();
    const auto t0 = Clock::now();
    int rounds = 0;
    do {
      (void)mat.advance_source(1e-3, b);
      ++rounds;
    } while (seconds_since(t0) < 0.05 && rounds < 100);
    worst = std::max(worst, seconds_since(t0) / (rounds * static_cast<double>(kCount)) * 1e9);
  }
  return worst;
}

// What `run` builds before its first step, checked the same way (the probes included); the
// summary line of a sound case, and with `estimate` the run-time line.
template <int Dim>
std::string check_run_case(const CaseDocument& document, bool estimate) {
  const CaseSetup<Dim> setup = read_case<Dim>(document);
  Simulation<Dim> solver(setup);
  const io::FieldCatalogue<Dim> node_fields(solver, io::FieldCatalogue<Dim>::Set::nodes);
  for (const ProbeSpec& spec : setup.probes) {
    (void)probe_node(spec, solver.nodes(), setup.dx);
    for (const auto& f : spec.fields) (void)probe_field(spec, f, node_fields);
  }
  const double dt = solver.clock().initial_dt();
  const double steps = std::ceil(setup.end_time / dt - 1e-9);
  const Index nodes = solver.nodes().size();
  std::string line = fmt::format(
      "{} {}D, {} nodes, {} stress points, {} rigid bod{}; dt = {:.4g} s{}, {:.0f} steps to "
      "{:.4g} s ({:.3g} node-steps)",
      setup.version, Dim, nodes, solver.stress_points().size(), setup.bodies.size(),
      setup.bodies.size() == 1 ? "y" : "ies", dt,
      setup.dt_from_current_state ? " at the start (from the current state)" : "", steps, setup.end_time,
      steps * static_cast<double>(nodes));
  if (!estimate) return line;
  // A few trial steps (at most 20, or about a second) as the run will take them.
  const auto t0 = Clock::now();
  int taken = 0;
  try {
    while (taken < 20 && taken < steps && (taken < 2 || seconds_since(t0) < 1.0)) {
      solver.step();
      ++taken;
    }
  } catch (const std::exception& e) {
    return line + fmt::format("\n      estimate: the trial steps stopped after {}: {}", taken, e.what());
  }
  if (taken == 0) return line;
  const double per_step = seconds_since(t0) / taken;
  const double elastic_total = per_step * steps;
  line += fmt::format("\n      estimate: {} on {} thread{} ({:.3g} node-steps/s over {} trial steps)",
                      duration_text(elastic_total), omp_get_max_threads(), omp_get_max_threads() == 1 ? "" : "s",
                      static_cast<double>(nodes) * taken / seconds_since(t0), taken);
  const double ns = plastic_return_ns(solver);
  if (ns > 0.0) {
    // Every node and stress point integrated by backward Euler at every step, spread on the threads.
    const double plastic = steps * static_cast<double>(nodes + solver.stress_points().size()) * ns * 1e-9 /
                           std::max(1, omp_get_max_threads());
    line += fmt::format("; up to {} if every particle flows plastically ({:.0f} ns a backward-Euler return)",
                        duration_text(elastic_total + plastic), ns);
  }
  return line;
}

std::string check_one(const std::string& file, const std::vector<std::string>& overrides, bool estimate) {
  CaseDocument document = load_case_document(file, overrides);
  if (document.table.contains("path")) {
    // A material-point file (`rktsph material-point`): its own reader checks it.
    const MaterialPointCase c = load_material_point_case(file, overrides);
    return fmt::format("material point, {} path", c.path_type);
  }
  const int dim = case_dimension(document);
  if (dim == 1) return check_run_case<1>(document, estimate);
  if (dim == 3) return check_run_case<3>(document, estimate);
  return check_run_case<2>(document, estimate);
}

}  // namespace

int check_cases(const CheckOptions& options) {
  if (options.threads > 0) omp_set_num_threads(options.threads);
  int bad = 0;
  for (const std::string& file : options.files) {
    try {
      std::cout << fmt::format("ok    {}: {}\n", file, check_one(file, options.overrides, options.estimate));
    } catch (const InputError& e) {
      ++bad;
      std::cout << fmt::format("error {}\n", e.what());
    } catch (const std::exception& e) {
      ++bad;
      std::cout << fmt::format("error {}: {}\n", file, e.what());
    }
  }
  if (options.files.size() > 1) {
    std::cout << fmt::format("{} of {} case files sound\n", options.files.size() - static_cast<std::size_t>(bad),
                             options.files.size());
  }
  return bad == 0 ? 0 : 2;
}

}  // namespace rktsph
