#pragma once
// `rktsph material-point FILE.toml [--out DIR]`: drive one homogeneous stress point along a
// load path (materials/material_point_path.hpp) and write DIR/path.csv, DIR/summary.json and,
// when /usr/bin/python3 has matplotlib, DIR/path.png. Case format: docs/materials.md.
#include <memory>
#include <string>
#include <vector>

#include "case/material_point_reader.hpp"

namespace rktsph {

/// Header: t,exx,eyy,ezz,exy,sxx,syy,szz,sxy,p,q,<state names>.
void write_path_csv(const std::string& file, const Material& material, const PathResult& result);

/// The whole command. Returns the exit status: 0, 2 (input error) or 3 (solver error); the
/// message of an error is printed to stderr.
int run_material_point(const std::string& case_file, const std::string& out_dir,
                       const std::vector<std::string>& overrides);

}  // namespace rktsph
