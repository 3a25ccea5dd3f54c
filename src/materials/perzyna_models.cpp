#include "materials/perzyna_models.hpp"

#include <cmath>

#include <fmt/format.h>

#include "io/section.hpp"
#include "materials/hardening.hpp"
#include "materials/perzyna.hpp"
#include "materials/yield_cam_clay.hpp"
#include "materials/yield_von_mises.hpp"

namespace rktsph {

Overstress read_overstress(const io::Section& s) {
  Overstress o;
  const std::string kind = s.string("overstress", "power");
  if (kind == "power") {
    o.kind = OverstressKind::power;
  } else if (kind == "exponential") {
    o.kind = OverstressKind::exponential;
  } else {
    s.fail("overstress",
           fmt::format("unknown overstress function '{}' (known: power, exponential)", kind));
  }
  o.exponent = s.positive("exponent", 1.0);
  // METHOD.md §6 item 12: no dead band unless a case asks for one (the lineage used 0.01).
  o.dead_band = s.non_negative("dead_band", 0.0);
  return o;
}

namespace {
double read_fluidity(const io::Section& s) {
  const double g = s.number("fluidity");
  s.require(g > 0.0, "fluidity",
            fmt::format("the Perzyna fluidity gamma must be > 0 1/s, got {}", g));
  return g;
}
}  // namespace

std::unique_ptr<Material> make_perzyna_von_mises(const io::Section& s) {
  const ElasticConstants el = read_elastic_constants(s);
  const bool has_y = s.has("yield_stress");
  const bool has_c = s.has("cohesion");
  if (has_y == has_c) {
    s.fail(has_y ? "cohesion" : "yield_stress",
           "give exactly one of 'yield_stress' (sigma_Y, Pa) and 'cohesion' (plane-strain "
           "shear strength c, Pa; sigma_Y = sqrt(3) c)");
  }
  // CASES.md §1.2 C2: sigma_Y = sqrt(3) c, c the plane-strain (Tresca) shear strength.
  const double Y0 = has_y ? s.positive("yield_stress") : std::sqrt(3.0) * s.positive("cohesion");
  LinearHardening h;
  h.Y0 = Y0;
  h.H = s.number("hardening_modulus", 0.0);
  h.Y_residual = s.number("residual_yield_stress", 0.1 * Y0);
  s.require(h.Y_residual > 0.0 && h.Y_residual <= Y0, "residual_yield_stress",
            fmt::format("the residual yield stress must lie in (0, {}] Pa (the initial yield "
                        "stress), got {}",
                        Y0, h.Y_residual));
  const double gamma = read_fluidity(s);
  const Overstress o = read_overstress(s);
  return std::make_unique<PerzynaMaterial<VonMisesSurface, LinearHardening>>(
      "perzyna_von_mises", el, VonMisesSurface{}, h, o, gamma);
}

std::unique_ptr<Material> make_perzyna_cam_clay(const io::Section& s) {
  const ElasticConstants el = read_elastic_constants(s);
  CamClaySurface surf;
  const bool has_M = s.has("M");
  const bool has_phi = s.has("critical_state_friction_angle");
  if (has_M == has_phi) {
    s.fail(has_M ? "critical_state_friction_angle" : "M",
           "give exactly one of 'M' (critical-state slope) and 'critical_state_friction_angle' "
           "(degrees)");
  }
  if (has_M) {
    surf.M_c = s.number("M");
    s.require(surf.M_c > 0.0, "M", fmt::format("M must be > 0, got {}", surf.M_c));
    s.require(surf.M_c < 3.0, "M",
              fmt::format("M must be < 3 (sin phi_c = 3M/(6+M) < 1), got {}", surf.M_c));
  } else {
    const double phi = s.number("critical_state_friction_angle");
    s.require(phi > 0.0 && phi < 90.0, "critical_state_friction_angle",
              fmt::format("the friction angle must lie in (0, 90) degrees, got {}", phi));
    surf.M_c = CamClaySurface::M_from_friction_angle(phi);
  }
  surf.lode_dependent = s.boolean("lode_dependent_M", false);

  const double lambda = s.positive("lambda");
  const double kappa = s.positive("kappa");
  s.require(lambda - kappa > 0.0, "kappa",
            fmt::format("negative lambda-kappa: the virgin slope lambda ({}) must exceed the "
                        "swelling slope kappa ({})",
                        lambda, kappa));
  const double e0 = s.positive("e0");
  CamClayHardening h;
  h.v0_over_lambda_kappa = (1.0 + e0) / (lambda - kappa);
  const bool has_pc = s.has("p_c0");
  const bool has_ocr = s.has("ocr");
  if (has_pc == has_ocr) {
    s.fail(has_pc ? "ocr" : "p_c0",
           "give exactly one of 'p_c0' (initial preconsolidation pressure, Pa) and 'ocr' "
           "(p_c0 = ocr times the equivalent size of the initial stress)");
  }
  if (has_pc) {
    h.p_c0 = s.number("p_c0");
    s.require(h.p_c0 > 0.0, "p_c0",
              fmt::format("the preconsolidation pressure must be > 0 Pa, got {}", h.p_c0));
  } else {
    h.ocr = s.number("ocr");
    s.require(h.ocr >= 1.0, "ocr", fmt::format("the OCR must be >= 1, got {}", h.ocr));
  }
  const double gamma = read_fluidity(s);
  const Overstress o = read_overstress(s);
  return std::make_unique<PerzynaMaterial<CamClaySurface, CamClayHardening>>(
      "perzyna_cam_clay", el, surf, h, o, gamma);
}

}  // namespace rktsph
