#pragma once
// Reading the limit-equilibrium problem from a case file (docs/case-format.md,
// "Limit equilibrium"): the same bodies ([[geometry.polygon]] or [[geometry.block]]), material
// and gravity as the particle case, and the rigid regions from its [[boundary]] entries.
#include <string>
#include <vector>

#include "case/case_reader.hpp"
#include "lem/bishop.hpp"
#include "lem/slope_geometry.hpp"

namespace rktsph::lem {

struct LemProblem {
  SoilGeometry geometry;
  Soil soil;
  std::string title;
  std::string material_name;
  std::string model;
  double density = 0.0;  // kg/m^3
  double gravity = 0.0;  // m/s^2, magnitude
  std::vector<std::string> notes;  // what the analysis leaves out of this case (printed, in lem.json)
};

/// Every error names the file, the line and the key (InputError, exit status 2).
LemProblem read_lem_problem(const CaseDocument& doc);

}  // namespace rktsph::lem
