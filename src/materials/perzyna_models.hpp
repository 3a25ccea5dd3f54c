#pragma once
// The Perzyna models, built from plain parameter structs (the keys that fill them are in
// docs/materials.md and are read by case/material_reader.cpp).
#include <memory>

#include "materials/material.hpp"
#include "materials/overstress.hpp"
#include "materials/tension_cutoff.hpp"
#include "materials/yield_drucker_prager.hpp"
#include "materials/yield_mohr_coulomb.hpp"

namespace rktsph {

/// perzyna_von_mises (method-notes §1.7): Y = max(Y0 + H eps_vp_eq, Y_residual).
struct VonMisesParameters {
  ElasticConstants elastic;
  double yield_stress = 0.0;           // Y0, Pa (docs/cases.md §1.2 C2: sqrt(3) c for a cohesion c)
  double hardening_modulus = 0.0;      // H, Pa (negative: softening)
  double residual_yield_stress = 0.0;  // floor of Y, Pa
  double fluidity = 0.0;               // gamma, 1/s
  Overstress overstress;
};
std::unique_ptr<Material> make_perzyna_von_mises(const VonMisesParameters& parameters);

/// Elasticity of perzyna_cam_clay: constant E and nu (the default), or the pressure-dependent
/// bulk modulus K = (1 + e0) p'/kappa (method-notes eqs. (1.8.8)–(1.8.9)).
enum class CamClayElasticity { constant, pressure_dependent };
/// The shear modulus with pressure-dependent K: constant Poisson's ratio or constant G.
enum class CamClayShear { poisson, constant_G };

/// perzyna_cam_clay (method-notes §1.8): modified Cam-Clay with p_c hardening.
struct CamClayParameters {
  ElasticConstants elastic;  // constant elasticity; pressure-dependent uses density and nu only
  CamClayElasticity elasticity = CamClayElasticity::constant;
  CamClayShear shear = CamClayShear::poisson;  // pressure-dependent only
  double shear_modulus = 0.0;                  // G, Pa (pressure-dependent, constant_G)
  double elastic_p_min = 0.0;                  // Pa: floor of p' in K (pressure-dependent)
  double elastic_p_max = 0.0;                  // Pa: cap of p' in K, sets the time step
  double M = 1.0;                              // critical-state slope in triaxial compression
  bool lode_dependent_M = false;               // M(theta) instead of constant M
  double lambda = 0.0;                         // virgin compression slope
  double kappa = 0.0;                          // swelling slope
  double e0 = 0.0;                             // initial void ratio
  double p_c0 = 0.0;                           // Pa; used when > 0
  double ocr = 0.0;                            // used when p_c0 = 0: p_c0 = ocr x the size of the initial stress
  double fluidity = 0.0;                       // gamma, 1/s
  Overstress overstress;
};
std::unique_ptr<Material> make_perzyna_cam_clay(const CamClayParameters& parameters);

/// perzyna_drucker_prager (method-notes §1.10): cone fitted to (c, phi), potential of
/// dilatancy psi, c = max(c0 + H_c eps_vp_eq, c_residual).
struct DruckerPragerParameters {
  ElasticConstants elastic;
  double cohesion = 0.0;        // c0, Pa, > 0
  double friction_angle = 0.0;  // phi, radians, in [0, pi/2)
  double dilatancy = 0.0;       // psi, radians, in [0, phi]
  DruckerPragerMatch match = DruckerPragerMatch::plane_strain;
  double apex_rounding = 0.1;      // eps of delta = eps sin(angle) Y, in [0, 1)
  double hardening_modulus = 0.0;  // H_c = dc/d eps_vp_eq, Pa (negative: softening)
  double residual_cohesion = 0.0;  // floor of c, Pa, in (0, c0]
  TensionCutoff tension_cutoff;    // largest mean stress, Pa (method-notes §1.12); off by default
  double fluidity = 0.0;           // gamma, 1/s
  Overstress overstress;
};
std::unique_ptr<Material> make_perzyna_drucker_prager(const DruckerPragerParameters& parameters);

/// perzyna_mohr_coulomb (method-notes §1.11): Abbo–Sloan rounded pyramid, potential of
/// dilatancy psi, c = max(c0 + H_c eps_vp_eq, c_residual). The keys of Drucker–Prager but
/// dp_match, plus lode_transition.
struct MohrCoulombParameters {
  ElasticConstants elastic;
  double cohesion = 0.0;           // c0, Pa, > 0
  double friction_angle = 0.0;     // phi, radians, in [0, pi/2)
  double dilatancy = 0.0;          // psi, radians, in [0, phi]
  double apex_rounding = 0.1;      // eps of delta = eps sin(angle) Y, in [0, 1)
  double hardening_modulus = 0.0;  // H_c = dc/d eps_vp_eq, Pa (negative: softening)
  double residual_cohesion = 0.0;  // floor of c, Pa, in (0, c0]
  TensionCutoff tension_cutoff;    // largest mean stress, Pa (method-notes §1.12); off by default
  double fluidity = 0.0;           // gamma, 1/s
  Overstress overstress;
  // theta_T of the Lode rounding, radians (eq. 1.11.2; key lode_transition, in degrees).
  double lode_transition = LodeFactor::kDefaultTransition;
};
std::unique_ptr<Material> make_perzyna_mohr_coulomb(const MohrCoulombParameters& parameters);

}  // namespace rktsph
