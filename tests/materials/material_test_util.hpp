#pragma once
// Helpers shared by the material tests: build a model from TOML text through the registry.
#include <memory>
#include <string>

#include <toml++/toml.h>

#include "case/material_reader.hpp"
#include "io/section.hpp"
#include "materials/material.hpp"

namespace rktsph::test {

/// Build a model from the body of a [material] table, as a case file would.
inline std::unique_ptr<Material> material_from_toml(const std::string& body, const std::string& file = "test.toml") {
  const toml::table root = toml::parse("[material]\n" + body, file);
  const io::Section top(root, "", std::make_shared<const std::string>(file));
  const io::Section mat = top.table("material");
  auto m = read_material(mat);
  mat.finish();
  return m;
}

/// von Mises, E = 10 MPa, nu = 0.3, Y = 100 kPa, with the given fluidity (1/s) and extra keys.
inline std::string von_mises(double fluidity, const std::string& extra = "") {
  return "model = 'perzyna_von_mises'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\n"
         "yield_stress = 1.0e5\nfluidity = " +
         std::to_string(fluidity) + "\n" + extra;
}

inline const std::string kCamClayCase3 =
    "model = 'perzyna_cam_clay'\nE = 2.0e7\nnu = 0.3\ndensity = 2000.0\nM = 1.2\n"
    "lambda = 0.2\nkappa = 0.02\ne0 = 1.0\np_c0 = 4.0e5\nfluidity = 10.0\n";

}  // namespace rktsph::test
