#pragma once
// Reading constitutive models from a case file's material tables: the one registry of model
// names (`model = "..."`), each with a reader that fills the model's parameter struct
// (materials/perzyna_models.hpp) and checks every value with file, line and key.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "materials/material.hpp"

namespace rktsph {
namespace io {
class Section;
}

/// Build the model named by the table's `model` key. An unknown name is an input error listing
/// the known ones. The caller owns the table (and calls finish()).
std::unique_ptr<Material> read_material(const io::Section& section);
/// Names and one-line descriptions of the registered models (`rktsph materials`).
std::vector<std::pair<std::string, std::string>> registered_materials();
/// E, nu and density with the physical checks (E > 0, -1 < nu < 0.5, density > 0).
ElasticConstants read_elastic_constants(const io::Section& section);

}  // namespace rktsph
