#pragma once
// The reader of one [[body]] entry of a case file (docs/case-format.md, "Rigid bodies"): a rigid
// plane, segment or polyline with its contact law and motion. Internal to src/case; every error
// names the file, the line and the key.
#include "case/case_setup.hpp"
#include "io/section.hpp"

namespace rktsph::case_reading {

/// One [[body]] entry (2D); `index` numbers the default name.
BodySpec read_body(const io::Section& b, const CaseSetup<2>& c, std::size_t index);

}  // namespace rktsph::case_reading
