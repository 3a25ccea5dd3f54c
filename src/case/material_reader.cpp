// The one registry of constitutive models: a case file's `model = "..."` picks one here.
// Add a model by adding one line to models() and a reader that fills its parameter struct.
#include "case/material_reader.hpp"

#include <cmath>
#include <functional>
#include <numbers>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/section.hpp"
#include "materials/perzyna_models.hpp"
#include "materials/yield_cam_clay.hpp"

namespace rktsph {

ElasticConstants read_elastic_constants(const io::Section& s) {
  const double E = s.number("E");
  s.require(E > 0.0, "E", fmt::format("Young's modulus must be > 0 Pa, got {}", E));
  const double nu = s.number("nu");
  s.require(nu > -1.0 && nu < 0.5, "nu", fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", nu));
  const double rho = s.number("density");
  s.require(rho > 0.0, "density", fmt::format("density must be > 0 kg/m^3, got {}", rho));
  return ElasticConstants::from_E_nu(E, nu, rho);
}

namespace {

// The overstress keys shared by the Perzyna models: overstress, exponent, dead_band.
Overstress read_overstress(const io::Section& s) {
  Overstress o;
  const std::string kind = s.string("overstress", "power");
  if (kind == "power") {
    o.kind = OverstressKind::power;
  } else if (kind == "exponential") {
    o.kind = OverstressKind::exponential;
  } else {
    s.fail("overstress", fmt::format("unknown overstress function '{}' (known: power, exponential)", kind));
  }
  o.exponent = s.positive("exponent", 1.0);
  // method-notes §6 item 12: no dead band unless a case asks for one (the lineage used 0.01).
  o.dead_band = s.non_negative("dead_band", 0.0);
  return o;
}

// gamma in 1/s, or "inf": the rate-independent limit (method-notes §2.5).
double read_fluidity(const io::Section& s) {
  const double g = s.number_or_infinity("fluidity");
  s.require(g > 0.0, "fluidity",
            fmt::format("the Perzyna fluidity gamma must be > 0 1/s (or \"inf\" for the rate-independent limit), got {}", g));
  return g;
}

std::unique_ptr<Material> read_elastic(const io::Section& s) {
  return std::make_unique<ElasticMaterial>(read_elastic_constants(s));
}

std::unique_ptr<Material> read_perzyna_von_mises(const io::Section& s) {
  VonMisesParameters p;
  p.elastic = read_elastic_constants(s);
  const bool has_y = s.has("yield_stress");
  const bool has_c = s.has("cohesion");
  if (has_y == has_c) {
    s.fail(has_y ? "cohesion" : "yield_stress",
           "give exactly one of 'yield_stress' (sigma_Y, Pa) and 'cohesion' (plane-strain "
           "shear strength c, Pa; sigma_Y = sqrt(3) c)");
  }
  // docs/cases.md §1.2 C2: sigma_Y = sqrt(3) c, c the plane-strain (Tresca) shear strength.
  const double Y0 = has_y ? s.positive("yield_stress") : std::sqrt(3.0) * s.positive("cohesion");
  p.yield_stress = Y0;
  p.hardening_modulus = s.number("hardening_modulus", 0.0);
  p.residual_yield_stress = s.number("residual_yield_stress", 0.1 * Y0);
  s.require(p.residual_yield_stress > 0.0 && p.residual_yield_stress <= Y0, "residual_yield_stress",
            fmt::format("the residual yield stress must lie in (0, {}] Pa (the initial yield "
                        "stress), got {}",
                        Y0, p.residual_yield_stress));
  p.fluidity = read_fluidity(s);
  p.overstress = read_overstress(s);
  return make_perzyna_von_mises(p);
}

// The pressure-dependent elasticity keys of perzyna_cam_clay (method-notes eqs. (1.8.8)–(1.8.9)):
// shear, nu or G, density, elastic_p_min, elastic_p_max.
void read_pressure_dependent_elasticity(const io::Section& s, CamClayParameters& p) {
  p.elasticity = CamClayElasticity::pressure_dependent;
  const std::string shear = s.string("shear", "poisson");
  if (shear == "poisson") {
    p.shear = CamClayShear::poisson;
    p.elastic.nu = s.number("nu");
    s.require(p.elastic.nu > -1.0 && p.elastic.nu < 0.5, "nu",
              fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", p.elastic.nu));
  } else if (shear == "constant_G") {
    p.shear = CamClayShear::constant_G;
    p.shear_modulus = s.number("G");
    s.require(p.shear_modulus > 0.0, "G", fmt::format("the shear modulus must be > 0 Pa, got {}", p.shear_modulus));
  } else {
    s.fail("shear", fmt::format("unknown shear law '{}' (known: poisson, constant_G)", shear));
  }
  p.elastic.density = s.number("density");
  s.require(p.elastic.density > 0.0, "density", fmt::format("density must be > 0 kg/m^3, got {}", p.elastic.density));
  p.elastic_p_min = s.number("elastic_p_min");
  s.require(p.elastic_p_min > 0.0, "elastic_p_min",
            fmt::format("the floor of p' in K = (1+e0) p'/kappa must be > 0 Pa, got {}", p.elastic_p_min));
  p.elastic_p_max = s.number("elastic_p_max");
  s.require(
      p.elastic_p_max > p.elastic_p_min, "elastic_p_max",
      fmt::format("the cap of p' in K must exceed elastic_p_min ({} Pa), got {}", p.elastic_p_min, p.elastic_p_max));
}

std::unique_ptr<Material> read_perzyna_cam_clay(const io::Section& s) {
  CamClayParameters p;
  const std::string elasticity = s.string("elasticity", "constant");
  if (elasticity == "constant") {
    p.elastic = read_elastic_constants(s);
  } else if (elasticity == "pressure_dependent") {
    read_pressure_dependent_elasticity(s, p);
  } else {
    s.fail("elasticity", fmt::format("unknown elasticity '{}' (known: constant, pressure_dependent)", elasticity));
  }
  const bool has_M = s.has("M");
  const bool has_phi = s.has("critical_state_friction_angle");
  if (has_M == has_phi) {
    s.fail(has_M ? "critical_state_friction_angle" : "M",
           "give exactly one of 'M' (critical-state slope) and 'critical_state_friction_angle' "
           "(degrees)");
  }
  if (has_M) {
    p.M = s.number("M");
    s.require(p.M > 0.0, "M", fmt::format("M must be > 0, got {}", p.M));
    s.require(p.M < 3.0, "M", fmt::format("M must be < 3 (sin phi_c = 3M/(6+M) < 1), got {}", p.M));
  } else {
    const double phi = s.number("critical_state_friction_angle");
    s.require(phi > 0.0 && phi < 90.0, "critical_state_friction_angle",
              fmt::format("the friction angle must lie in (0, 90) degrees, got {}", phi));
    p.M = CamClaySurface::M_from_friction_angle(phi);
  }
  p.lode_dependent_M = s.boolean("lode_dependent_M", false);
  p.lambda = s.positive("lambda");
  p.kappa = s.positive("kappa");
  s.require(p.lambda - p.kappa > 0.0, "kappa",
            fmt::format("negative lambda-kappa: the virgin slope lambda ({}) must exceed the "
                        "swelling slope kappa ({})",
                        p.lambda, p.kappa));
  p.e0 = s.positive("e0");
  const bool has_pc = s.has("p_c0");
  const bool has_ocr = s.has("ocr");
  if (has_pc == has_ocr) {
    s.fail(has_pc ? "ocr" : "p_c0",
           "give exactly one of 'p_c0' (initial preconsolidation pressure, Pa) and 'ocr' "
           "(p_c0 = ocr times the equivalent size of the initial stress)");
  }
  if (has_pc) {
    p.p_c0 = s.number("p_c0");
    s.require(p.p_c0 > 0.0, "p_c0", fmt::format("the preconsolidation pressure must be > 0 Pa, got {}", p.p_c0));
  } else {
    p.ocr = s.number("ocr");
    s.require(p.ocr >= 1.0, "ocr", fmt::format("the OCR must be >= 1, got {}", p.ocr));
  }
  p.fluidity = read_fluidity(s);
  p.overstress = read_overstress(s);
  return make_perzyna_cam_clay(p);
}

// The friction angle in degrees, in [0, 90); returned in radians.
double read_friction_angle(const io::Section& s) {
  const double deg = s.number("friction_angle");
  s.require(deg >= 0.0 && deg < 90.0, "friction_angle",
            fmt::format("the friction angle must lie in [0, 90) degrees, got {}", deg));
  return deg * std::numbers::pi / 180.0;
}

// The keys shared by the frictional models (method-notes §1.10–1.11): all but dp_match.
template <class Parameters>
void read_frictional(const io::Section& s, Parameters& p) {
  p.elastic = read_elastic_constants(s);
  p.cohesion = s.number("cohesion");
  s.require(p.cohesion > 0.0, "cohesion",
            fmt::format("the cohesion must be > 0 Pa (Y = xi c normalises the overstress; give a small c "
                        "for a cohesionless soil), got {}",
                        p.cohesion));
  p.friction_angle = read_friction_angle(s);
  const double phi_deg = s.number("friction_angle");
  const double psi_deg = s.number("dilatancy", 0.0);
  s.require(psi_deg >= 0.0 && psi_deg <= phi_deg, "dilatancy",
            fmt::format("the dilatancy angle must lie in [0, {}] degrees (0 <= psi <= the friction angle), got {}",
                        phi_deg, psi_deg));
  p.dilatancy = psi_deg * std::numbers::pi / 180.0;
  p.apex_rounding = s.number("apex_rounding", 0.1);
  s.require(p.apex_rounding >= 0.0 && p.apex_rounding < 1.0, "apex_rounding",
            fmt::format("the apex rounding must lie in [0, 1), got {}", p.apex_rounding));
  p.hardening_modulus = s.number("hardening_modulus", 0.0);
  p.residual_cohesion = s.number("residual_cohesion", 0.1 * p.cohesion);
  s.require(p.residual_cohesion > 0.0 && p.residual_cohesion <= p.cohesion, "residual_cohesion",
            fmt::format("the residual cohesion must lie in (0, {}] Pa (the initial cohesion), got {}", p.cohesion,
                        p.residual_cohesion));
  // The tension cut-off on the mean stress (method-notes §1.12): absent, none. Beyond the sharp
  // apex c cot(phi) it would bound no state the shear surface admits.
  if (s.has("tension_cutoff")) {
    p.tension_cutoff.active = true;
    p.tension_cutoff.limit = s.number("tension_cutoff");
    const double apex = p.friction_angle > 0.0 ? p.cohesion / std::tan(p.friction_angle) : 0.0;
    if (p.friction_angle > 0.0) {
      s.require(p.tension_cutoff.limit >= 0.0 && p.tension_cutoff.limit <= apex, "tension_cutoff",
                fmt::format("the tension cut-off (largest mean stress) must lie in [0, {}] Pa (the apex c cot(phi)), "
                            "got {}",
                            apex, p.tension_cutoff.limit));
    } else {
      s.require(
          p.tension_cutoff.limit >= 0.0, "tension_cutoff",
          fmt::format("the tension cut-off (largest mean stress) must be >= 0 Pa, got {}", p.tension_cutoff.limit));
    }
  }
  p.fluidity = read_fluidity(s);
  p.overstress = read_overstress(s);
}

std::unique_ptr<Material> read_perzyna_drucker_prager(const io::Section& s) {
  DruckerPragerParameters p;
  read_frictional(s, p);
  const std::string match = s.string("dp_match", "plane_strain");
  if (match == "plane_strain") {
    p.match = DruckerPragerMatch::plane_strain;
  } else if (match == "outer") {
    p.match = DruckerPragerMatch::outer;
  } else if (match == "inner") {
    p.match = DruckerPragerMatch::inner;
  } else {
    s.fail("dp_match", fmt::format("unknown Drucker-Prager match '{}' (known: plane_strain, outer, inner)", match));
  }
  return make_perzyna_drucker_prager(p);
}

std::unique_ptr<Material> read_perzyna_mohr_coulomb(const io::Section& s) {
  MohrCoulombParameters p;
  read_frictional(s, p);
  const double transition = s.number("lode_transition", LodeFactor::kDefaultTransitionDegrees);
  s.require(transition >= LodeFactor::kMinTransitionDegrees && transition <= LodeFactor::kMaxTransitionDegrees,
            "lode_transition",
            fmt::format("the Lode transition angle must lie in [{}, {}] degrees, got {}",
                        LodeFactor::kMinTransitionDegrees, LodeFactor::kMaxTransitionDegrees, transition));
  p.lode_transition = transition * std::numbers::pi / 180.0;
  return make_perzyna_mohr_coulomb(p);
}

struct Entry {
  const char* name;
  const char* description;
  std::function<std::unique_ptr<Material>(const io::Section&)> read;
};

const std::vector<Entry>& models() {
  static const std::vector<Entry> kModels = {
      {"elastic", "isotropic linear (hypo-)elastic: E, nu, density", read_elastic},
      {"perzyna_von_mises", "Perzyna viscoplastic von Mises with linear hardening/softening (history: eps_vp_eq)",
       read_perzyna_von_mises},
      {"perzyna_cam_clay",
       "Perzyna viscoplastic modified Cam-Clay with p_c hardening, constant or pressure-dependent elasticity "
       "(history: eps_vp_eq, eps_vp_vol, p_c)",
       read_perzyna_cam_clay},
      {"perzyna_drucker_prager",
       "Perzyna viscoplastic Drucker-Prager (c, phi, dilatancy, rounded apex, tension cut-off, c softening; "
       "history: eps_vp_eq)",
       read_perzyna_drucker_prager},
      {"perzyna_mohr_coulomb",
       "Perzyna viscoplastic Mohr-Coulomb, Abbo-Sloan rounding (c, phi, dilatancy, tension cut-off, c softening; "
       "history: eps_vp_eq)",
       read_perzyna_mohr_coulomb},
  };
  return kModels;
}

}  // namespace

std::unique_ptr<Material> read_material(const io::Section& section) {
  const std::string name = section.string("model");
  for (const Entry& e : models()) {
    if (name == e.name) return e.read(section);
  }
  std::vector<std::string> known;
  for (const Entry& e : models()) known.emplace_back(e.name);
  section.fail("model", fmt::format("unknown material model '{}' (known models: {})", name, fmt::join(known, ", ")));
}

std::vector<std::pair<std::string, std::string>> registered_materials() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : models()) out.emplace_back(e.name, e.description);
  return out;
}

}  // namespace rktsph
