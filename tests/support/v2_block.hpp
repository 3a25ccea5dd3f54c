// The V2 tests' 2 m x 2 m elastic block (E = 10 MPa, nu = 0.3, rho = 2000 kg/m^3) centred at the
// origin on a 0.1 m lattice, free faces, to 1 s at C = 0.5.
#pragma once

#include <string>

#include "case/case_builder.hpp"

namespace rktsph::test {

inline CaseBuilder<2> v2_block(const std::string& name) {
  CaseBuilder<2> b(name);
  b.spacing(0.1)
      .origin(Vec<2>(-1.0, -1.0))
      .block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2")
      .time(1.0, 0.5);
  return b;
}

}  // namespace rktsph::test
