#pragma once
// Reading and checking a TOML case file into a CaseSetup (docs/case-format.md). The only code
// that knows TOML is here and in io/section.hpp. Every error names the file, the line and the
// key, and is an InputError (exit status 2).
#include <memory>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "case/case_setup.hpp"

namespace rktsph {
namespace io {
class Section;
}

/// A TOML case file, parsed, with the command-line overrides (--set key=value) applied.
struct CaseDocument {
  std::string file;
  std::shared_ptr<const std::string> file_label;
  /// The folder that relative paths in the case (geometry.particles) start from: the case
  /// file's own folder.
  std::string directory;
  toml::table table;
};

CaseDocument load_case_document(const std::string& file, const std::vector<std::string>& overrides);
/// The same from the text of a case (a checkpoint's copy of it); `label` names it in errors.
CaseDocument parse_case_document(const std::string& text, const std::string& label,
                                 const std::vector<std::string>& overrides);
/// Apply one --set key=value to a parsed document: the value is one TOML value (or a bare word,
/// read as a string); array-of-tables entries are indexed from 0 (boundary.1.stress.xx). Throws
/// InputError naming `file` and the assignment.
void apply_override(toml::table& root, const std::string& assignment, const std::string& file);
/// The value of an override as the document "v = value"; `label` starts its error messages.
toml::table parse_override_value(const std::string& label, const std::string& text);
/// The dimension of space of a case (geometry.dimension), checked.
int case_dimension(const CaseDocument& doc);

template <int Dim>
CaseSetup<Dim> read_case(const CaseDocument& doc);

/// One [functions.NAME] table.
TimeFunction read_time_function(const io::Section& section);

}  // namespace rktsph
