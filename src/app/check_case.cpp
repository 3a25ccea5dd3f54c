#include "app/check_case.hpp"

#include <cmath>
#include <exception>
#include <iostream>

#include <fmt/format.h>

#include "app/run_loop.hpp"
#include "case/case_reader.hpp"
#include "case/material_point_reader.hpp"
#include "core/error.hpp"
#include "io/field_catalogue.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {

namespace {

// What `run` builds before its first step, checked the same way (the probes included); the
// summary line of a sound case.
template <int Dim>
std::string check_run_case(const CaseDocument& document) {
  const CaseSetup<Dim> setup = read_case<Dim>(document);
  const Simulation<Dim> solver(setup);
  const io::FieldCatalogue<Dim> node_fields(solver, io::FieldCatalogue<Dim>::Set::nodes);
  for (const ProbeSpec& spec : setup.probes) {
    (void)probe_node(spec, solver.nodes(), setup.dx);
    for (const auto& f : spec.fields) (void)probe_field(spec, f, node_fields);
  }
  const double dt = solver.clock().initial_dt();
  const double steps = std::ceil(setup.end_time / dt - 1e-9);
  const Index nodes = solver.nodes().size();
  return fmt::format(
      "{} {}D, {} nodes, {} stress points, {} rigid bod{}; dt = {:.4g} s{}, {:.0f} steps to "
      "{:.4g} s ({:.3g} node-steps)",
      setup.version, Dim, nodes, solver.stress_points().size(), setup.bodies.size(),
      setup.bodies.size() == 1 ? "y" : "ies", dt,
      setup.dt_from_current_state ? " at the start (from the current state)" : "", steps, setup.end_time,
      steps * static_cast<double>(nodes));
}

std::string check_one(const std::string& file, const std::vector<std::string>& overrides) {
  CaseDocument document = load_case_document(file, overrides);
  if (document.table.contains("path")) {
    // A material-point file (`rktsph material-point`): its own reader checks it.
    const MaterialPointCase c = load_material_point_case(file, overrides);
    return fmt::format("material point, {} path", c.path_type);
  }
  const int dim = case_dimension(document);
  if (dim == 1) return check_run_case<1>(document);
  if (dim == 3) return check_run_case<3>(document);
  return check_run_case<2>(document);
}

}  // namespace

int check_cases(const CheckOptions& options) {
  int bad = 0;
  for (const std::string& file : options.files) {
    try {
      std::cout << fmt::format("ok    {}: {}\n", file, check_one(file, options.overrides));
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
