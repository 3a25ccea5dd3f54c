// The one registry of constitutive models: a case file's `model = "..."` picks one here.
// Add a model by adding one line to kModels.
#include <functional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"
#include "io/section.hpp"
#include "materials/material.hpp"
#include "materials/perzyna_models.hpp"

namespace rktsph {
namespace {

struct Entry {
  const char* name;
  const char* description;
  std::function<std::unique_ptr<Material>(const io::Section&)> make;
};

std::unique_ptr<Material> make_elastic(const io::Section& s) {
  return std::make_unique<ElasticMaterial>(read_elastic_constants(s));
}

const std::vector<Entry>& models() {
  static const std::vector<Entry> kModels = {
      {"elastic", "isotropic linear (hypo-)elastic: E, nu, density", make_elastic},
      {"perzyna_von_mises", "Perzyna viscoplastic von Mises with linear hardening/softening",
       make_perzyna_von_mises},
      {"perzyna_cam_clay", "Perzyna viscoplastic modified Cam-Clay with p_c hardening",
       make_perzyna_cam_clay},
  };
  return kModels;
}

}  // namespace

std::unique_ptr<Material> create_material(const io::Section& section) {
  const std::string name = section.string("model");
  for (const Entry& e : models()) {
    if (name == e.name) return e.make(section);
  }
  std::vector<std::string> known;
  for (const Entry& e : models()) known.emplace_back(e.name);
  section.fail("model", fmt::format("unknown material model '{}' (known models: {})", name,
                                    fmt::join(known, ", ")));
}

std::vector<std::pair<std::string, std::string>> registered_materials() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : models()) out.emplace_back(e.name, e.description);
  return out;
}

}  // namespace rktsph
