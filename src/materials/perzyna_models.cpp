#include "materials/perzyna_models.hpp"

#include <cmath>

#include "core/error.hpp"

#include "materials/hardening.hpp"
#include "materials/perzyna.hpp"
#include "materials/yield_cam_clay.hpp"
#include "materials/yield_drucker_prager.hpp"
#include "materials/yield_mohr_coulomb.hpp"
#include "materials/yield_von_mises.hpp"

namespace rktsph {

std::unique_ptr<Material> make_perzyna_von_mises(const VonMisesParameters& p) {
  LinearHardening h;
  h.Y0 = p.yield_stress;
  h.H = p.hardening_modulus;
  h.Y_residual = p.residual_yield_stress;
  return std::make_unique<PerzynaMaterial<VonMisesSurface, LinearHardening>>(
      "perzyna_von_mises", p.elastic, VonMisesSurface{}, h, p.overstress, p.fluidity);
}

std::unique_ptr<Material> make_perzyna_cam_clay(const CamClayParameters& p) {
  CamClaySurface surf;
  surf.M_c = p.M;
  surf.lode_dependent = p.lode_dependent_M;
  CamClayHardening h;
  h.v0_over_lambda_kappa = (1.0 + p.e0) / (p.lambda - p.kappa);
  h.p_c0 = p.p_c0;
  h.ocr = p.ocr;
  if (p.elasticity == CamClayElasticity::constant) {
    return std::make_unique<PerzynaMaterial<CamClaySurface, CamClayHardening>>("perzyna_cam_clay", p.elastic, surf, h,
                                                                               p.overstress, p.fluidity);
  }
  // Pressure-dependent moduli (method-notes eqs. (1.8.8)–(1.8.9)); the reference constants are
  // those at p_max, the stiffest state, which sets the time step.
  if (!(p.kappa > 0.0 && p.e0 > 0.0 && p.elastic_p_min > 0.0 && p.elastic_p_max > p.elastic_p_min)) {
    throw InputError(
        "perzyna_cam_clay: pressure-dependent elasticity needs kappa > 0, e0 > 0 and "
        "0 < elastic_p_min < elastic_p_max");
  }
  PressureDependentModuli moduli;
  moduli.v0_over_kappa = (1.0 + p.e0) / p.kappa;
  moduli.constant_shear = p.shear == CamClayShear::constant_G;
  moduli.G_over_K = 1.5 * (1.0 - 2.0 * p.elastic.nu) / (1.0 + p.elastic.nu);
  moduli.G_constant = p.shear_modulus;
  moduli.p_min = p.elastic_p_min;
  moduli.p_max = p.elastic_p_max;
  const double K_max = moduli.bulk_modulus(p.elastic_p_max);
  const ElasticConstants reference = ElasticConstants::from_K_G(K_max, moduli.shear_modulus(K_max), p.elastic.density);
  return std::make_unique<PerzynaMaterial<CamClaySurface, CamClayHardening>>("perzyna_cam_clay", reference, surf, h,
                                                                             p.overstress, p.fluidity, moduli);
}

std::unique_ptr<Material> make_perzyna_drucker_prager(const DruckerPragerParameters& p) {
  const DruckerPragerCone cone = DruckerPragerCone::matched(p.match, p.friction_angle, p.dilatancy);
  DruckerPragerSurface surf;
  surf.eta = cone.eta;
  surf.eta_flow = cone.eta_flow;
  surf.round_F = p.apex_rounding * std::sin(p.friction_angle);
  surf.round_Q = p.apex_rounding * std::sin(p.dilatancy);
  // Y = xi c (eq. 1.10.1) with the linear law of c (eq. 1.10.8).
  LinearHardening h;
  h.Y0 = cone.xi * p.cohesion;
  h.H = cone.xi * p.hardening_modulus;
  h.Y_residual = cone.xi * p.residual_cohesion;
  return std::make_unique<PerzynaMaterial<DruckerPragerSurface, LinearHardening>>(
      "perzyna_drucker_prager", p.elastic, surf, h, p.overstress, p.fluidity, PressureDependentModuli{},
      p.tension_cutoff);
}

std::unique_ptr<Material> make_perzyna_mohr_coulomb(const MohrCoulombParameters& p) {
  const MohrCoulombSurface surf =
      MohrCoulombSurface::make(p.friction_angle, p.dilatancy, p.apex_rounding, p.lode_transition);
  // Y = sqrt(3) cos(phi) c (eq. 1.11.1) with the linear law of c (eq. 1.10.8).
  const double xi = std::sqrt(3.0) * std::cos(p.friction_angle);
  LinearHardening h;
  h.Y0 = xi * p.cohesion;
  h.H = xi * p.hardening_modulus;
  h.Y_residual = xi * p.residual_cohesion;
  return std::make_unique<PerzynaMaterial<MohrCoulombSurface, LinearHardening>>(
      "perzyna_mohr_coulomb", p.elastic, surf, h, p.overstress, p.fluidity, PressureDependentModuli{},
      p.tension_cutoff);
}

}  // namespace rktsph
