#pragma once
// A node lattice of (n + 1) x (m + 1) nodes at spacing dx with tributary volumes (halved on the
// faces, quartered at the corners), density 1700 kg/m^3: the pressure-system tests' set.
#include "particles/particle_set.hpp"

namespace rktsph::test {

inline ParticleSet<2> node_lattice(int n, int m, double dx) {
  ParticleSet<2> s;
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i <= n; ++i) {
      s.position.emplace_back(i * dx, j * dx);
      const double fx = (i == 0 || i == n) ? 0.5 : 1.0, fy = (j == 0 || j == m) ? 0.5 : 1.0;
      s.volume.push_back(fx * fy * dx * dx);
      s.density.push_back(1700.0);
      s.material.push_back(0);
    }
  }
  return s;
}

}  // namespace rktsph::test
