// The V2 tests' 2 m x 2 m elastic block (E = 10 MPa, nu = 0.3, rho = 2000 kg/m^3) centred at the
// origin on a 0.1 m lattice, free faces, to 1 s at C = 0.5; and the rotation and checkerboard
// checks that the V2 stress tests share.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "case/case_builder.hpp"
#include "schemes/simulation.hpp"

namespace rktsph::test {

inline CaseBuilder<2> v2_block(const std::string& name) {
  CaseBuilder<2> b(name);
  b.spacing(0.1)
      .origin(Vec<2>(-1.0, -1.0))
      .block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2")
      .time(1.0, 0.5);
  return b;
}

/// The thesis's simple scheme for step 2's velocity (solver.velocity_update = "simple",
/// method-notes §2.3) instead of V2's default hourglass control: the tests of the simple scheme's
/// own options (its weight, the stress blend and filter) use it.
template <int Dim>
inline CaseSetup<Dim> simple_scheme(CaseSetup<Dim> c) {
  c.simple_velocity = true;
  c.hourglass = false;
  return c;
}

/// +1 / -1 on the two colours of the test block's 0.1 m node lattice (positions from -1 m): the
/// nodal checkerboard, which no stress point of the lattice sees.
inline std::vector<double> lattice_checkerboard(const std::vector<Vec<2>>& position) {
  std::vector<double> sign(position.size());
  for (std::size_t i = 0; i < sign.size(); ++i) {
    const long ix = std::lround((position[i][0] + 1.0) / 0.1), iy = std::lround((position[i][1] + 1.0) / 0.1);
    sign[i] = (ix + iy) % 2 == 0 ? 1.0 : -1.0;
  }
  return sign;
}

/// The rigid-rotation check of the V2 Jaumann tests: the initial uniform stress (sxx, syy, szz,
/// sxy) = (-1e4, -3e4, -2e4, 5e3) Pa rotated counter-clockwise by theta, R sigma R^T, against the
/// nodes that started within `half_width` of the centre (by id: V2 sorts its nodes as they
/// move). Returns the largest difference, Pa, and the count of nodes checked.
struct RotationCheck {
  double worst = 0.0;
  int nodes = 0;
};
inline RotationCheck rotated_stress_error(const Simulation<2>& sim, const std::vector<Vec<2>>& start, double theta,
                                          double half_width) {
  const double a = -1.0e4, d = -3.0e4, b = 5.0e3, zz = -2.0e4;
  const double c = std::cos(theta), s = std::sin(theta);
  const double xx = c * c * a - 2.0 * c * s * b + s * s * d;
  const double yy = s * s * a + 2.0 * c * s * b + c * c * d;
  const double xy = c * s * (a - d) + (c * c - s * s) * b;
  RotationCheck r;
  const auto stress = sim.node_stress();
  const std::vector<Index> at = sim.nodes_by_id();
  for (std::size_t k = 0; k < start.size(); ++k) {
    if (std::abs(start[k][0]) > half_width || std::abs(start[k][1]) > half_width) continue;
    const Index i = at[k];
    ++r.nodes;
    r.worst =
        std::max({r.worst, std::abs(stress(i, StressComponent::xx) - xx), std::abs(stress(i, StressComponent::yy) - yy),
                  std::abs(stress(i, StressComponent::xy) - xy), std::abs(stress(i, StressComponent::zz) - zz)});
  }
  return r;
}

/// The V2 Jaumann tests' block: 10 m, 0.1 m lattice, elastic with a density that makes it
/// stiff against its own inertia, the uniform stress of rotated_stress_error, a quarter turn of
/// rigid rotation in `steps` fixed steps (`spin_rigidly`).
inline CaseBuilder<2> rotation_block(const std::string& name, int steps) {
  CaseBuilder<2> b(name);
  b.spacing(0.1)
      .origin(Vec<2>(-5.0, -5.0))
      .block(Vec<2>(-5.0, -5.0), Vec<2>(5.0, 5.0))
      .elastic(1.0e7, 0.3, 1.0e20)
      .scheme("v2")
      .initial_stress({-1.0e4, -3.0e4, -2.0e4, 5.0e3, 0.0, 0.0})
      .time_step(1.0, 1.0 / steps);
  return b;
}

/// Rigid rotation at pi/2 rad/s about the origin, the velocity reset to omega x x before every
/// one of `steps` steps; then the rigid-rotation check of the nodes that started within
/// `half_width` of the centre (0.5 m: what the faces' traction-free stress cannot reach in 8
/// steps of the 10 m rotation_block, each step's interpolations spreading it by at most 4.8 dx).
inline RotationCheck spin_rigidly(Simulation<2>& sim, int steps, double half_width = 0.5) {
  const double omega = std::numbers::pi / 2.0;
  const std::vector<Vec<2>> start = sim.nodes().position;
  for (int n = 0; n < steps; ++n) {
    auto v = sim.mutable_node_velocity();
    for (std::size_t i = 0; i < sim.nodes().position.size(); ++i) {
      const auto& x = sim.nodes().position[i];
      v(i, 0) = -omega * x[1];
      v(i, 1) = omega * x[0];
    }
    sim.step();
  }
  return rotated_stress_error(sim, start, omega * sim.time(), half_width);
}

/// The amplitude of a nodal checkerboard of sign `sign` (lattice_checkerboard of the start
/// positions `start`) on stress component `read`, over the nodes that started 0.5 m or more
/// inside the test block's faces, relative to `scale`.
inline double interior_checkerboard_amplitude(const Simulation<2>& sim, const std::vector<double>& sign,
                                              const std::vector<Vec<2>>& start, StressComponent read, double scale) {
  const auto now = sim.node_stress();
  const std::vector<Index> at = sim.nodes_by_id();
  double sum = 0.0;
  long count = 0;
  for (std::size_t k = 0; k < start.size(); ++k) {
    if (std::abs(start[k][0]) > 0.5 + 1e-9 || std::abs(start[k][1]) > 0.5 + 1e-9) continue;
    sum += sign[k] * now(at[k], read);
    ++count;
  }
  return std::abs(sum) / static_cast<double>(count) / scale;
}

}  // namespace rktsph::test
