#pragma once
// Registry makers of the Perzyna models (keys documented in docs/materials.md). They read
// their keys from the material table but do not call finish(): the caller owns the table.
#include <memory>

#include "materials/material.hpp"
#include "materials/overstress.hpp"

namespace rktsph {
namespace io {
class Section;
}

/// fluidity-free part of the Perzyna keys: overstress, exponent, dead_band.
Overstress read_overstress(const io::Section& section);

/// perzyna_von_mises: METHOD.md §1.7, CASES.md §1.2 C2.
std::unique_ptr<Material> make_perzyna_von_mises(const io::Section& section);
/// perzyna_cam_clay: METHOD.md §1.8, CASES.md §1.2 C3.
std::unique_ptr<Material> make_perzyna_cam_clay(const io::Section& section);

}  // namespace rktsph
