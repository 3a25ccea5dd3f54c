#include "materials/perzyna_models.hpp"

#include "materials/hardening.hpp"
#include "materials/perzyna.hpp"
#include "materials/yield_cam_clay.hpp"
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
  return std::make_unique<PerzynaMaterial<CamClaySurface, CamClayHardening>>("perzyna_cam_clay", p.elastic, surf, h,
                                                                             p.overstress, p.fluidity);
}

}  // namespace rktsph
