#pragma once
// Shared by the saturated validation cases 13-17: the pressure stage of a run, and measures of a
// nodal pore-pressure field on the regular particle lattice.
#include <vector>

#include "schemes/pressure_stage.hpp"
#include "schemes/simulation.hpp"

namespace rktsph::validation {

/// The pressure stage of a saturated run (throws SolverError naming `who` if the run is dry).
template <int Dim>
const PorePressureStage<Dim>& pressure_stage(const Simulation<Dim>& solver, const char* who) {
  const auto* stage = solver.scheme().template find<PorePressureStage<Dim>>();
  if (stage == nullptr) throw SolverError(std::string(who) + ": the case file is not a V3 (saturated) case");
  return *stage;
}

/// Odd-even (checkerboard) content of a nodal field f on the regular lattice of spacing dx.
/// At every node whose 5-point stencils along x and along y lie inside the body, the
/// alternating component is estimated by the fourth difference
///   a_x = |f_{i-2} - 4 f_{i-1} + 6 f_i - 4 f_{i+1} + f_{i+2}| / 16
/// (and a_y alike): a node-to-node alternation A (-1)^i (or a checkerboard A (-1)^(i+j))
/// gives exactly |A|, while a smooth field gives dx^4 |f''''| / 16, zero for any cubic, so the
/// measure does not mistake smooth curvature (boundary layers, gravity gradients) for
/// oscillation. Returns max over nodes of max(a_x, a_y); `rms` receives its root mean square.
/// Nodes with `skip[i]` true (e.g. drained nodes, where p_w is prescribed and a pressure
/// boundary layer thinner than dx is a step, not an oscillation) are left out of every stencil.
double checkerboard_amplitude(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& f,
                              double dx, double* rms = nullptr, const std::vector<bool>* skip = nullptr);

}  // namespace rktsph::validation
