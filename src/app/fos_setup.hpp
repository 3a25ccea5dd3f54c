#pragma once
// What `rktsph fos` reads from a case (docs/fos.md): the strength keys of its materials and how a
// factor F reduces them (method-notes §10, eq. (10.1)), the [fos] table (monitor, reference
// length, classification window, search settings) and the monitored node.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/fos_search.hpp"
#include "case/case_reader.hpp"

namespace rktsph::fos {

/// One material's strength and its reduction by F.
struct MaterialStrength {
  std::string table;  // "material" or "materials.NAME"
  std::string model;
  /// Keys divided by F, with their unreduced values: the cohesion (or yield stress) and, where
  /// the case gives them, the softening modulus and the residual strength.
  std::vector<std::pair<std::string, double>> divided;
  std::optional<double> friction_angle;  // degrees: tan(phi_F) = tan(phi) / F
  std::optional<double> dilatancy;       // degrees: psi_F = min(psi, phi_F)
};

struct StrengthReduction {
  std::vector<MaterialStrength> materials;
  std::vector<std::string> unreduced;  // tables of elastic materials, kept as they are
  /// The --set overrides that give the case at factor F (method-notes eq. (10.1)).
  std::vector<std::string> overrides(double factor) const;
  /// The reduced values at F, as "table.key" -> value.
  std::vector<std::pair<std::string, double>> values(double factor) const;
};

/// Read the materials of a case (already checked by the case reader). InputError, naming the
/// file, the line and the key `model`, for a material whose strength cannot be reduced
/// (Cam-Clay) or when no material has a strength (all elastic).
StrengthReduction read_strength(const CaseDocument& doc);

/// phi_F = atan(tan(phi) / F), degrees in and out (method-notes eq. (10.1)).
double reduced_friction_angle(double phi_degrees, double factor);

/// The [fos] table (every key optional).
struct FosTable {
  std::optional<std::string> monitor_probe;          // monitor = "probe name"
  std::optional<std::vector<double>> monitor_point;  // monitor = [x, y]
  std::optional<std::vector<double>> direction;      // unit vector of the monitored displacement
  std::optional<double> length;                      // m: H of a cut, B of a footing
  double window = 1.0;                               // s: the classification window
  SearchSettings search;
  std::string where;  // "case.toml, line N, key 'fos'" for messages
};
FosTable read_fos_table(const CaseDocument& doc);

/// The monitored node and the classification's scales, resolved on the case's particles.
struct Monitor {
  std::vector<double> position;   // the node's initial position, m
  std::vector<double> direction;  // unit vector; u_c = u . direction
  double length = 0.0;            // m
  double window = 1.0;            // s
  std::string source;             // how it was chosen, for the report
};
/// InputError (file, line, key 'fos.monitor') when the probe is not in the case or the point
/// is not on the body.
Monitor resolve_monitor(const CaseDocument& doc, const FosTable& table);

/// The name of the probe `rktsph fos` adds to every trial, and the override that adds it to the
/// case's own probes: probe = [ ...the case's..., { name = "fos_monitor", ... } ].
inline constexpr const char* kMonitorProbe = "fos_monitor";
std::string monitor_probe_override(const CaseDocument& doc, const Monitor& monitor);

}  // namespace rktsph::fos
