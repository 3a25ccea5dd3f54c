#pragma once
// Homogeneous material-point driver: integrates one stress point along a mixed stress/strain
// controlled load path (no SPH). Each of the six tensor components (xx, yy, zz, xy, yz, xz)
// is either strain-controlled (given eps_dot) or stress-controlled (given sigma_dot, usually
// 0). The full rate
//     sigma_dot = D^e : (eps_dot - eps_vp_dot(sigma, kappa)),  kappa_dot = h(sigma, kappa)
// is solved for the unknown strain rates of the stress-controlled components from the
// elastic partition, and integrated by classical RK4, sub-stepped against the model's
// relaxation rate; where that would take more than Material::max_explicit_substeps sub-steps,
// a step is integrated by the model's backward Euler instead (method-notes §2.5), the
// stress-controlled components met by Newton. The axial direction of the named triaxial paths is y.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "materials/material.hpp"

namespace rktsph {

enum class Control { strain, stress };

struct LoadPath {
  std::array<Control, 6> control{Control::strain, Control::strain, Control::strain,
                                 Control::strain, Control::strain, Control::strain};
  Sym6 rate{};            // eps_dot (tensor shear) for strain-controlled, sigma_dot for stress-controlled
  double duration = 0.0;  // s
  double dt = 0.0;        // s, output/step interval; <= 0 picks duration/1000
  int output_every = 1;   // steps between recorded points (the first and last are always kept)
  /// Sub-steps keep relaxation_rate * h <= this (accuracy, well inside RK4's limit 2.78).
  double relaxation_target = 0.5;

  /// Named paths (axial = y, compression for a negative axial rate):
  /// drained (conventional) triaxial: eps_yy rate, sigma_xx and sigma_zz constant.
  static LoadPath drained_triaxial(double axial_rate);
  /// undrained (isochoric) triaxial: eps_xx = eps_zz = -axial/2.
  static LoadPath undrained_triaxial(double axial_rate);
  /// oedometric: eps_yy rate, eps_xx = eps_zz = 0.
  static LoadPath oedometric(double axial_rate);
  /// plane-strain (biaxial) compression: eps_yy rate, sigma_xx constant, eps_zz = 0.
  static LoadPath plane_strain_compression(double axial_rate);
  /// simple shear: engineering shear rate gamma_dot = 2 eps_xy_dot, all other strains fixed.
  static LoadPath simple_shear(double shear_rate);
};

struct PathPoint {
  double t = 0.0;
  Sym6 strain{};  // total strain, tensor shear components, positive in extension
  Sym6 stress{};  // Pa, positive in tension
  std::vector<double> state;
};

struct PathResult {
  std::vector<PathPoint> points;
  long steps = 0;
  long substeps = 0;                 // total RK4 sub-steps
  long implicit_steps = 0;           // steps integrated by backward Euler (method-notes §2.5)
  long newton_iterations = 0;        // the Newton iterations of their returns
  double max_relaxation_rate = 0.0;  // 1/s, largest estimate met
};

/// Integrate a material point from the initial stress sigma0 (history variables from
/// Material::initial_state). Throws SolverError if the state becomes non-finite.
PathResult integrate_path(const Material& material, const Sym6& sigma0, const LoadPath& path);

}  // namespace rktsph
