#pragma once
// A material-point file read and checked (docs/materials.md): the model, the initial stress
// and the load path of `rktsph material-point`.
#include <memory>
#include <string>
#include <vector>

#include "materials/material.hpp"
#include "materials/material_point_path.hpp"

namespace rktsph {

struct MaterialPointCase {
  std::unique_ptr<Material> material;
  Sym6 sigma0{};  // Pa, tension positive
  LoadPath path;
  std::string path_type;    // the [path] type key
  std::string plot_strain;  // strain component on the plot's abscissa ("yy", "xy", ...)
  bool plot = true;
};

/// Read and check a case file; overrides are "dotted.key=value" (a TOML value; a bare word is
/// a string). Throws InputError naming file, line and key.
MaterialPointCase load_material_point_case(const std::string& case_file, const std::vector<std::string>& overrides);

}  // namespace rktsph
