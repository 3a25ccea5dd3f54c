#pragma once
// Parts of the case reader (case/case_reader.cpp) kept in their own files: the small helpers
// every section uses, and the readers of one boundary entry, one probe and the particle files.
// Internal to src/case.
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "case/case_reader.hpp"
#include "io/section.hpp"

namespace rktsph::case_reading {

template <int Dim>
Vec<Dim> read_vector(const io::Section& s, std::string_view key) {
  const auto v = s.numbers(key);
  if (static_cast<int>(v.size()) != Dim) {
    s.fail(key, fmt::format("must have {} component{} for a {}D case, got {}", Dim, Dim > 1 ? "s" : "", Dim, v.size()));
  }
  Vec<Dim> out;
  for (int d = 0; d < Dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

inline int axis_of(std::string_view name) {
  for (std::size_t d = 0; d < 3; ++d) {
    if (kAxisNames[d] == name) return static_cast<int>(d);
  }
  return -1;
}

template <int Dim>
int function_index(const CaseSetup<Dim>& c, const io::Section& s, std::string_view key) {
  if (!s.has(key)) {
    s.string(key, "");  // mark as read
    return -1;
  }
  const std::string name = s.string(key);
  for (std::size_t i = 0; i < c.function_names.size(); ++i) {
    if (c.function_names[i] == name) return static_cast<int>(i);
  }
  s.fail(key, fmt::format("no time function named '{}' (defined: {})", name,
                          c.function_names.empty() ? std::string("none")
                                                   : fmt::format("{}", fmt::join(c.function_names, ", "))));
}

inline int material_index(const std::vector<std::string>& names, const io::Section& s, std::string_view key) {
  if (!s.has(key)) {
    s.string(key, "");
    if (names.size() == 1) return 0;
    s.fail(key, fmt::format("several materials are defined ({}); name the block's material", fmt::join(names, ", ")));
  }
  const std::string name = s.string(key);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
  }
  s.fail(key, fmt::format("no material named '{}' (defined: {})", name, fmt::join(names, ", ")));
}

/// One [[boundary]] entry: its region and what it prescribes.
template <int Dim>
BoundarySpec<Dim> read_boundary(const io::Section& b, const CaseSetup<Dim>& c);

/// One [initial_velocity] table or [[initial_velocity]] entry.
template <int Dim>
InitialVelocitySpec<Dim> read_initial_velocity(const io::Section& s, const CaseSetup<Dim>& c);

/// One [[probe]] entry.
template <int Dim>
ProbeSpec read_probe(const io::Section& p, const CaseSetup<Dim>& c);

// [[geometry.particles]]: each entry names a CSV file of nodes and one of stress points
// (case/particle_file_reader.hpp), relative to the case file's folder; the entries' particles
// make one set each. No two particles of a set may coincide (within 1e-6 spacings, the
// tolerance with which boundary entries select nodes).
template <int Dim>
typename CaseSetup<Dim>::ImportedParticles read_imported_particles(const CaseDocument& doc,
                                                                   const std::vector<io::Section>& entries,
                                                                   const CaseSetup<Dim>& c);

}  // namespace rktsph::case_reading
