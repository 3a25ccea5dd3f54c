// The material-point command: case-file reading, bad input, output format.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/material_point.hpp"
#include "core/error.hpp"

namespace rktsph {
namespace {

namespace fs = std::filesystem;

const std::string kGoodMaterial =
    "[material]\nmodel = 'perzyna_cam_clay'\nE = 2e7\nnu = 0.3\ndensity = 2000\nM = 1.2\n"
    "lambda = 0.2\nkappa = 0.02\ne0 = 1.0\np_c0 = 1e5\nfluidity = 10\n";
const std::string kGoodRest =
    "[initial]\nstress = { xx = -1e5, yy = -1e5, zz = -1e5 }\n"
    "[path]\ntype = 'drained_triaxial'\naxial_strain_rate = -0.01\nduration = 1.0\n";

std::string write_case(const std::string& name, const std::string& text) {
  const fs::path p = fs::path(::testing::TempDir()) / name;
  std::ofstream(p) << text;
  return p.string();
}

// Replace "key = ..." in the good material (the whole line) or append it.
std::string with(const std::string& key, const std::string& line) {
  std::string m = kGoodMaterial;
  const auto pos = m.find("\n" + key + " = ");
  if (pos != std::string::npos) {
    const auto end = m.find('\n', pos + 1);
    m = m.substr(0, pos + 1) + line + m.substr(end);
  } else {
    m += line + "\n";
  }
  return m + kGoodRest;
}

void expect_input_error(const std::string& name, const std::string& text, const std::string& key,
                        const std::string& phrase = "") {
  const std::string file = write_case(name, text);
  try {
    load_material_point_case(file, {});
    ADD_FAILURE() << name << ": no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(key), std::string::npos) << msg;
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
    if (!phrase.empty()) {
      EXPECT_NE(msg.find(phrase), std::string::npos) << msg;
    }
  }
}

TEST(MaterialPointCase, GoodCaseLoads) {
  const auto c = load_material_point_case(write_case("mp_good.toml", kGoodMaterial + kGoodRest), {});
  EXPECT_EQ(c.material->model(), "perzyna_cam_clay");
  EXPECT_EQ(c.path.control[0], Control::stress);
  EXPECT_EQ(c.path.control[1], Control::strain);
  EXPECT_DOUBLE_EQ(c.path.rate[1], -0.01);
  EXPECT_DOUBLE_EQ(c.sigma0[2], -1e5);
  EXPECT_DOUBLE_EQ(c.path.dt, 1e-3);  // default duration/1000
}

TEST(MaterialPointCase, BadMaterialInputNamesKeyAndFile) {
  expect_input_error("mp_lk.toml", with("kappa", "kappa = 0.3"), "material.kappa", "negative lambda-kappa");
  expect_input_error("mp_pc.toml", with("p_c0", "p_c0 = -5"), "material.p_c0");
  expect_input_error("mp_M.toml", with("M", "M = 0"), "material.M");
  expect_input_error("mp_fl.toml", with("fluidity", "fluidity = 0"), "material.fluidity");
  expect_input_error("mp_N.toml", with("exponent", "exponent = -1"), "material.exponent");
  expect_input_error("mp_os.toml", with("overstress", "overstress = 'cubic'"), "material.overstress", "cubic");
  expect_input_error("mp_ocr.toml", with("ocr", "ocr = 2"), "material.ocr", "exactly one");
  expect_input_error("mp_typo.toml", with("lamda", "lamda = 0.2"), "material.lamda", "unknown key");
  expect_input_error("mp_model.toml", with("model", "model = 'cam_clay'"), "material.model");
  const std::string vm =
      "[material]\nmodel = 'perzyna_von_mises'\nE = 1e7\nnu = 0.3\ndensity = 2000\n"
      "fluidity = 1\n";
  const std::string rest = "[path]\ntype = 'simple_shear'\nshear_strain_rate = 1\nduration = 1\n";
  expect_input_error("mp_vm_none.toml", vm + rest, "material.yield_stress", "exactly one");
  expect_input_error("mp_vm_both.toml", vm + "yield_stress = 1e5\ncohesion = 5e4\n" + rest, "material.cohesion",
                     "exactly one");
  expect_input_error("mp_vm_res.toml", vm + "yield_stress = 1e5\nresidual_yield_stress = 2e5\n" + rest,
                     "material.residual_yield_stress");
}

TEST(MaterialPointCase, BadDruckerPragerInputNamesKeyAndFile) {
  const std::string dp =
      "[material]\nmodel = 'perzyna_drucker_prager'\nE = 1e7\nnu = 0.3\ndensity = 2000\nfluidity = 1\n";
  const std::string good = "cohesion = 1e4\nfriction_angle = 30\n";
  const std::string rest = "[path]\ntype = 'simple_shear'\nshear_strain_rate = 1\nduration = 1\n";
  EXPECT_NO_THROW(load_material_point_case(write_case("mp_dp_good.toml", dp + good + rest), {}));
  expect_input_error("mp_dp_c.toml", dp + "cohesion = -1e4\nfriction_angle = 30\n" + rest, "material.cohesion",
                     "> 0 Pa");
  expect_input_error("mp_dp_c0.toml", dp + "cohesion = 0\nfriction_angle = 30\n" + rest, "material.cohesion");
  expect_input_error("mp_dp_nophi.toml", dp + "cohesion = 1e4\n" + rest, "material.friction_angle", "missing");
  expect_input_error("mp_dp_phineg.toml", dp + "cohesion = 1e4\nfriction_angle = -5\n" + rest,
                     "material.friction_angle", "[0, 90)");
  expect_input_error("mp_dp_phi90.toml", dp + "cohesion = 1e4\nfriction_angle = 90\n" + rest, "material.friction_angle",
                     "[0, 90)");
  expect_input_error("mp_dp_psi.toml", dp + good + "dilatancy = 35\n" + rest, "material.dilatancy",
                     "the friction angle");
  expect_input_error("mp_dp_psineg.toml", dp + good + "dilatancy = -1\n" + rest, "material.dilatancy");
  expect_input_error("mp_dp_match.toml", dp + good + "dp_match = 'middle'\n" + rest, "material.dp_match", "middle");
  expect_input_error("mp_dp_round.toml", dp + good + "apex_rounding = 1.0\n" + rest, "material.apex_rounding");
  expect_input_error("mp_dp_res.toml", dp + good + "residual_cohesion = 2e4\n" + rest, "material.residual_cohesion",
                     "(0, 10000]");
  expect_input_error("mp_dp_typo.toml", dp + good + "dilatency = 5\n" + rest, "material.dilatency", "unknown key");
  // The tension cut-off (method-notes §1.12): in [0, c cot(phi)] = [0, 17320.5] Pa here.
  EXPECT_NO_THROW(load_material_point_case(write_case("mp_dp_t.toml", dp + good + "tension_cutoff = 0\n" + rest), {}));
  expect_input_error("mp_dp_tneg.toml", dp + good + "tension_cutoff = -1\n" + rest, "material.tension_cutoff",
                     "largest mean stress");
  expect_input_error("mp_dp_tapex.toml", dp + good + "tension_cutoff = 1.8e4\n" + rest, "material.tension_cutoff",
                     "c cot(phi)");
  // lode_transition belongs to Mohr-Coulomb only.
  expect_input_error("mp_dp_lode.toml", dp + good + "lode_transition = 29\n" + rest, "material.lode_transition",
                     "unknown key");
}

TEST(MaterialPointCase, BadMohrCoulombInputNamesKeyAndFile) {
  const std::string mc =
      "[material]\nmodel = 'perzyna_mohr_coulomb'\nE = 1e7\nnu = 0.3\ndensity = 2000\nfluidity = 1\n";
  const std::string good = "cohesion = 1e4\nfriction_angle = 30\n";
  const std::string rest = "[path]\ntype = 'simple_shear'\nshear_strain_rate = 1\nduration = 1\n";
  const auto c = load_material_point_case(write_case("mp_mc_good.toml", mc + good + rest), {});
  EXPECT_EQ(c.material->model(), "perzyna_mohr_coulomb");
  expect_input_error("mp_mc_c.toml", mc + "cohesion = -1\nfriction_angle = 30\n" + rest, "material.cohesion");
  expect_input_error("mp_mc_phi.toml", mc + "cohesion = 1e4\nfriction_angle = 90\n" + rest, "material.friction_angle",
                     "[0, 90)");
  expect_input_error("mp_mc_psi.toml", mc + good + "dilatancy = 31\n" + rest, "material.dilatancy",
                     "the friction angle");
  // dp_match belongs to Drucker-Prager only.
  expect_input_error("mp_mc_match.toml", mc + good + "dp_match = 'outer'\n" + rest, "material.dp_match", "unknown key");
  // theta_T in [20, 29.9] degrees (method-notes §1.11); the cut-off as for Drucker-Prager, any
  // T >= 0 without friction (no apex).
  EXPECT_NO_THROW(
      load_material_point_case(write_case("mp_mc_lode.toml", mc + good + "lode_transition = 29.9\n" + rest), {}));
  expect_input_error("mp_mc_lode30.toml", mc + good + "lode_transition = 30\n" + rest, "material.lode_transition",
                     "[20, 29.9]");
  expect_input_error("mp_mc_lode19.toml", mc + good + "lode_transition = 19\n" + rest, "material.lode_transition",
                     "[20, 29.9]");
  expect_input_error("mp_mc_tapex.toml", mc + good + "tension_cutoff = 1e5\n" + rest, "material.tension_cutoff",
                     "c cot(phi)");
  EXPECT_NO_THROW(load_material_point_case(
      write_case("mp_mc_t0.toml", mc + "cohesion = 1e4\nfriction_angle = 0\ntension_cutoff = 1e6\n" + rest), {}));
  expect_input_error("mp_mc_t0neg.toml", mc + "cohesion = 1e4\nfriction_angle = 0\ntension_cutoff = -5\n" + rest,
                     "material.tension_cutoff", ">= 0 Pa");
}

// Pressure-dependent Cam-Clay elasticity (method-notes eq. (1.8.8)): its keys and their errors.
TEST(MaterialPointCase, BadPressureDependentElasticityNamesKeyLineAndFile) {
  const std::string pd =
      "[material]\nmodel = 'perzyna_cam_clay'\nelasticity = 'pressure_dependent'\nnu = 0.3\ndensity = 2000\n"
      "M = 1.2\nlambda = 0.2\nkappa = 0.02\ne0 = 1.0\np_c0 = 1e5\nfluidity = 10\nelastic_p_min = 1e3\n"
      "elastic_p_max = 1e7\n";
  auto replace = [&](const std::string& key, const std::string& line) {
    std::string m = pd;
    const auto pos = m.find("\n" + key + " = ");
    const auto end = m.find('\n', pos + 1);
    return m.substr(0, pos + 1) + line + m.substr(end) + kGoodRest;
  };
  const auto c = load_material_point_case(write_case("mp_pd_good.toml", pd + kGoodRest), {});
  EXPECT_TRUE(c.material->pressure_moduli().active());
  EXPECT_NO_THROW(
      load_material_point_case(write_case("mp_pd_G.toml", replace("nu", "shear = 'constant_G'\nG = 3e6") + ""), {}));
  expect_input_error("mp_pd_kind.toml", replace("elasticity", "elasticity = 'hyper'"), "material.elasticity", "hyper");
  expect_input_error("mp_pd_shear.toml", replace("nu", "shear = 'poison'\nnu = 0.3"), "material.shear", "poison");
  expect_input_error("mp_pd_kappa0.toml", replace("kappa", "kappa = 0"), "material.kappa", "> 0");
  expect_input_error("mp_pd_kappaneg.toml", replace("kappa", "kappa = -0.02"), "material.kappa", "> 0");
  expect_input_error("mp_pd_e0.toml", replace("e0", "# e0 missing"), "material.e0", "missing");
  expect_input_error("mp_pd_pmin.toml", replace("elastic_p_min", "elastic_p_min = 0"), "material.elastic_p_min",
                     "> 0 Pa");
  expect_input_error("mp_pd_nopmax.toml", replace("elastic_p_max", "# no cap"), "material.elastic_p_max", "missing");
  expect_input_error("mp_pd_pmax.toml", replace("elastic_p_max", "elastic_p_max = 500"), "material.elastic_p_max",
                     "exceed");
  expect_input_error("mp_pd_nu.toml", replace("nu", "nu = 0.5"), "material.nu", "(-1, 0.5)");
  expect_input_error("mp_pd_G0.toml", replace("nu", "shear = 'constant_G'\nG = 0"), "material.G", "> 0 Pa");
  // E is the constant law's key; G belongs to constant_G, nu to poisson; shear to pressure_dependent.
  expect_input_error("mp_pd_E.toml", replace("nu", "nu = 0.3\nE = 2e7"), "material.E", "unknown key");
  expect_input_error("mp_pd_Gnu.toml", replace("nu", "nu = 0.3\nG = 3e6"), "material.G", "unknown key");
  expect_input_error("mp_pd_shearc.toml", with("shear", "shear = 'poisson'"), "material.shear", "unknown key");
  // The errors name the line of the key.
  try {
    load_material_point_case(write_case("mp_pd_line.toml", replace("elastic_p_min", "elastic_p_min = -1")), {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 12"), std::string::npos) << e.what();
  }
}

TEST(MaterialPointCase, BadPathInputNamesKeyAndFile) {
  expect_input_error("mp_type.toml", kGoodMaterial + "[path]\ntype = 'triaxial'\nduration = 1\n", "path.type",
                     "triaxial");
  expect_input_error("mp_dur.toml",
                     kGoodMaterial +
                         "[path]\ntype = 'oedometric'\naxial_strain_rate = -1\n"
                         "duration = 0\n",
                     "path.duration");
  expect_input_error("mp_rate.toml", kGoodMaterial + "[path]\ntype = 'oedometric'\nduration = 1\n",
                     "path.axial_strain_rate", "missing");
  expect_input_error("mp_both.toml",
                     kGoodMaterial +
                         "[initial]\nstress = {xx = -1e5, yy = -1e5, zz = -1e5}\n"
                         "[path]\ntype = 'strain_rate'\nduration = 1\n"
                         "strain_rate = {yy = -0.01, xx = 0.0}\n"
                         "stress_rate = {xx = 0.0}\n",
                     "path.stress_rate.xx", "not both");
  // OCR with a tensile initial stress cannot define p_c.
  std::string t = with("p_c0", "ocr = 2");
  t.replace(t.find("xx = -1e5, yy = -1e5, zz = -1e5"), 31, "xx = 1e3, yy = 1e3, zz = 1e3");
  expect_input_error("mp_tens.toml", t, "initial", "compressive");
}

TEST(MaterialPointCase, RunWritesCsvWithTheDocumentedHeader) {
  const std::string file = write_case("mp_run.toml", kGoodMaterial + kGoodRest);
  const std::string out = (fs::path(::testing::TempDir()) / "mp_run_out").string();
  fs::remove_all(out);
  ASSERT_EQ(run_material_point(file, out, {"output.plot=false", "path.output_every=100"}), 0);
  std::ifstream in(fs::path(out) / "path.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "t,exx,eyy,ezz,exy,sxx,syy,szz,sxy,p,q,eps_vp_eq,eps_vp_vol,p_c");
  int rows = 0;
  std::string line, last;
  while (std::getline(in, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, 11);  // t = 0 and every 100 of 1000 steps
  std::stringstream ss(last);
  std::string cell;
  std::getline(ss, cell, ',');
  EXPECT_DOUBLE_EQ(std::stod(cell), 1.0);
  std::getline(ss, cell, ',');
  std::getline(ss, cell, ',');
  EXPECT_NEAR(std::stod(cell), -0.01, 1e-12);  // eyy = axial rate * duration
  EXPECT_TRUE(fs::exists(fs::path(out) / "summary.json"));
  // Input errors exit with status 2, including a bad override.
  EXPECT_EQ(run_material_point(file, out, {"material.fluidity=-1"}), 2);
  EXPECT_EQ(run_material_point(file + ".missing", out, {}), 2);
}

TEST(MaterialPointCase, ExampleCasesLoad) {
  for (const char* name :
       {"von_mises_shear.toml", "cam_clay_drained_nc.toml", "cam_clay_undrained_nc.toml", "cam_clay_case3_biaxial.toml",
        "drucker_prager_plane_strain.toml", "mohr_coulomb_triaxial.toml", "cam_clay_undrained_pressure_dependent.toml",
        "mohr_coulomb_tension_cutoff.toml"}) {
    const std::string f = std::string(RKTSPH_SOURCE_DIR) + "/cases/material_point/" + name;
    EXPECT_NO_THROW(load_material_point_case(f, {})) << name;
  }
}

}  // namespace
}  // namespace rktsph
