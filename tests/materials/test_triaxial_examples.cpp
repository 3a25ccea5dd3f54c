// Issue 16 item 5(c): the material-point example cases cases/examples/triaxial_*.toml, read as
// `rktsph material-point` reads them, against their closed-form peak strengths (criterion 1 %).
// The Mohr-Coulomb triaxial-compression peak is also set against the sharp pyramid, which the
// Abbo-Sloan rounding with the default theta_T = 29.7 deg misses by 0.45 % at phi = 30 deg
// (method-notes eq. (1.11.8); 1.49 % with the former 29 deg).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "case/material_point_reader.hpp"
#include "core/types.hpp"
#include "materials/yield_mohr_coulomb.hpp"

namespace rktsph {
namespace {

constexpr double kP0 = 1.0e5, kC = 1.0e4;
const double kSin = std::sin(30.0 * std::numbers::pi / 180.0), kCos = std::cos(30.0 * std::numbers::pi / 180.0);

PathResult run(const std::string& name) {
  const MaterialPointCase c =
      load_material_point_case(std::string(RKTSPH_SOURCE_DIR) + "/cases/examples/" + name + ".toml", {});
  // Every case: c = 10 kPa, phi = 30 deg, isotropic start at p0 = 100 kPa (the closed forms below).
  EXPECT_DOUBLE_EQ(c.sigma0[0], -kP0);
  return integrate_path(*c.material, c.sigma0, c.path);
}

double peak_q(const PathResult& r) {
  double q = 0.0;
  for (const PathPoint& p : r.points) q = std::max(q, invariants(p.stress).q);
  return q;
}

double peak_axial(const PathResult& r) {
  double s = 0.0;
  for (const PathPoint& p : r.points) s = std::max(s, -p.stress[1]);
  return s;
}

// Mohr-Coulomb in triaxial compression, sharp: q = 2 (c cos + p0 sin)/(1 - sin) = 234.64 kPa.
const double kSharpTriaxial = 2.0 * (kC * kCos + kP0 * kSin) / (1.0 - kSin);
// Plane strain, Mohr-Coulomb: sigma_1 = p0 (1 + sin)/(1 - sin) + 2 c cos/(1 - sin) = 334.64 kPa.
const double kPlaneStrain = kP0 * (1.0 + kSin) / (1.0 - kSin) + 2.0 * kC * kCos / (1.0 - kSin);

TEST(TriaxialExamples, DruckerPragerDrainedTriaxialPeak) {
  const double q = peak_q(run("triaxial_drucker_prager_drained"));
  const double err = (q - kSharpTriaxial) / kSharpTriaxial;
  std::printf("[ figures  ] DP outer drained triaxial: peak q %.2f kPa, closed form %.2f kPa, error %+.3f %%\n",
              q / 1e3, kSharpTriaxial / 1e3, 100 * err);
  EXPECT_LT(std::abs(err), 0.01);
}

TEST(TriaxialExamples, MohrCoulombDrainedTriaxialPeak) {
  const PathResult r = run("triaxial_mohr_coulomb_drained");
  const double q = peak_q(r);
  const double r3 = std::sqrt(3.0);
  const double rounded = r3 * (kC * kCos + kP0 * kSin) / (LodeFactor::of(kSin)(1.0).K - kSin / r3);
  const double err_rounded = (q - rounded) / rounded, err_sharp = (q - kSharpTriaxial) / kSharpTriaxial;
  std::printf(
      "[ figures  ] MC drained triaxial: peak q %.2f kPa; rounded closed form %.2f kPa (%+.3f %%); sharp "
      "pyramid %.2f kPa (%+.3f %%)\n",
      q / 1e3, rounded / 1e3, 100 * err_rounded, kSharpTriaxial / 1e3, 100 * err_sharp);
  // Within 1 % of the rounded surface's own closed form (eq. (1.11.6)) ...
  EXPECT_LT(std::abs(err_rounded), 0.01);
  // ... and of the sharp pyramid, the criterion of issue 16 (-0.45 % rate-independent at
  // theta_T = 29.7 deg; -1.49 % at the former 29 deg). The second check pins the stated figure.
  EXPECT_LT(std::abs(err_sharp), 0.01);
  EXPECT_NEAR(err_sharp, -0.0045, 0.0005);
  // theta_T = 29 deg, the former default, still reproduces its -1.49 % (the key lode_transition).
  const MaterialPointCase c29 =
      load_material_point_case(std::string(RKTSPH_SOURCE_DIR) + "/cases/examples/triaxial_mohr_coulomb_drained.toml",
                               {"material.lode_transition=29.0"});
  const PathResult r29 = integrate_path(*c29.material, c29.sigma0, c29.path);
  const double err29 = (peak_q(r29) - kSharpTriaxial) / kSharpTriaxial;
  std::printf(
      "[ figures  ] MC drained triaxial, theta_T = 29 deg: peak q %.2f kPa (%+.3f %% sharp); sub-steps %ld "
      "(29.7 deg: %ld)\n",
      peak_q(r29) / 1e3, 100 * err29, r29.substeps, r.substeps);
  EXPECT_NEAR(err29, -0.0148, 0.0005);
}

TEST(TriaxialExamples, DruckerPragerPlaneStrainPeak) {
  const double s = peak_axial(run("triaxial_drucker_prager_plane_strain"));
  const double err = (s - kPlaneStrain) / kPlaneStrain;
  std::printf(
      "[ figures  ] DP plane-strain match, plane-strain compression: peak sigma_1 %.2f kPa, closed form "
      "%.2f kPa, error %+.3f %%\n",
      s / 1e3, kPlaneStrain / 1e3, 100 * err);
  EXPECT_LT(std::abs(err), 0.01);
}

TEST(TriaxialExamples, MohrCoulombPlaneStrainPeak) {
  const double s = peak_axial(run("triaxial_mohr_coulomb_plane_strain"));
  const double err = (s - kPlaneStrain) / kPlaneStrain;
  std::printf(
      "[ figures  ] MC plane-strain compression: peak sigma_1 %.2f kPa, closed form %.2f kPa, error "
      "%+.3f %%\n",
      s / 1e3, kPlaneStrain / 1e3, 100 * err);
  EXPECT_LT(std::abs(err), 0.01);
}

}  // namespace
}  // namespace rktsph
