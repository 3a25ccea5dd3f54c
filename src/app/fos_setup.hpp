#pragma once
// What `rktsph fos` reads from a case (docs/fos.md): the strength keys of its materials and how a
// factor F reduces them (method-notes §10, eq. (10.1)), or the time functions of the loads a load
// factor F multiplies (eq. (10.4)); the [fos] table (what F scales, monitor, reference length,
// hold or classification window, search settings) and the monitored node. A trial's case is the
// document with its values set in place (apply): no text is parsed again.
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
  /// Trials in the rate-independent limit: every reduced material's fluidity set to "inf"
  /// (fos.rate_independent, default true; docs/fos.md "Rate independence").
  bool rate_independent = true;
  /// The reduced values at F, as "table.key" -> value (method-notes eq. (10.1)).
  std::vector<std::pair<std::string, double>> values(double factor) const;
  /// Write the case at factor F into `root` (a copy of the case's table): the reduced values
  /// and, if rate_independent, fluidity = inf in every reduced material.
  void apply(toml::table& root, double factor) const;
};

/// Read the materials of a case (already checked by the case reader). InputError, naming the
/// file, the line and the key `model`, for a material whose strength cannot be reduced
/// (Cam-Clay) or when no material has a strength (all elastic).
StrengthReduction read_strength(const CaseDocument& doc);

/// phi_F = atan(tan(phi) / F), degrees in and out (method-notes eq. (10.1)).
double reduced_friction_angle(double phi_degrees, double factor);

/// What a trial's factor F scales: the strengths, divided by F (the factor of safety by strength
/// reduction), or the loads, multiplied by F (the load factor of the collapse load).
enum class FactorMode { strength, load };

/// The load factor (method-notes eq. (10.4)): a trial at F multiplies the `scale` of each named
/// time function (every load the function scales) by F.
struct LoadScaling {
  /// "functions.NAME" and its unscaled `scale` (default 1).
  std::vector<std::pair<std::string, double>> functions;
  /// The scaled values at F, as "functions.NAME.scale" -> value.
  std::vector<std::pair<std::string, double>> values(double factor) const;
  /// Write the case at load factor F into `root` (a copy of the case's table).
  void apply(toml::table& root, double factor) const;
};

/// The [fos] table (every key optional).
struct FosTable {
  FactorMode mode = FactorMode::strength;            // mode = "strength" | "load"
  std::vector<std::string> load_functions;           // load_functions = ["NAME", ...] (mode "load")
  std::optional<std::string> monitor_probe;          // monitor = "probe name"
  std::optional<std::vector<double>> monitor_point;  // monitor = [x, y]
  std::optional<std::vector<double>> direction;      // unit vector of the monitored displacement
  std::optional<double> length;                      // m: H of a cut, B of a footing
  /// s: the hold after time.end over which a strength-reduction trial is judged (absent: eight
  /// time scales sqrt(L/g), or time.end without gravity; app/fos_criterion.hpp).
  std::optional<double> hold;
  bool rate_independent = true;                      // rate_independent = true | false
  double window = 1.0;                               // s: the load factor's classification window
  /// kinetic = "auto" (default) | "nodes" | "stress_points": whose kinetic energy the
  /// classification reads (energy.csv's `kinetic` or `kinetic_stress_points`); "auto" reads the
  /// stress points' for V2 trials and the nodes' otherwise (docs/fos.md, "Which kinetic energy").
  std::optional<bool> kinetic_of_stress_points;
  SearchSettings search;
  std::string where;  // "case.toml, line N, key 'fos'" for messages
};
/// InputError (file, line, key) for an unknown mode, load_functions without mode = "load" or
/// missing with it, a key of one mode given in the other (window and load_functions belong to
/// the load factor, hold and rate_independent to strength reduction).
FosTable read_fos_table(const CaseDocument& doc);

/// The time functions of fos.load_functions with their scales; InputError (file, line, key
/// 'fos.load_functions') for a name that is not a [functions.NAME] table of the case.
LoadScaling read_load_scaling(const CaseDocument& doc, const FosTable& table);

/// The monitored node and the classification's scales, resolved on the case's particles.
struct Monitor {
  std::vector<double> position;   // the node's initial position, m
  std::vector<double> direction;  // unit vector; u_c = u . direction
  double length = 0.0;            // m
  double window = 1.0;            // s: the load factor's classification window
  /// Strength reduction: the hold after time.end (s) and the slope's time scale sqrt(L/g) that
  /// sets its default (0 without gravity).
  double hold_start = 0.0;        // s: the case's time.end
  double hold = 0.0;              // s
  double time_scale = 0.0;        // s
  std::string kinetic_column = "kinetic";  // energy.csv's column the classification reads
  std::string source;             // how it was chosen, for the report
  // The case's resolution, for the report: a limit load converges with the smoothing length h,
  // not the spacing alone (docs/fos.md, "Resolution").
  double spacing = 0.0;           // m
  double smoothing_length = 0.0;  // m
};
/// InputError (file, line, key 'fos.monitor') when the probe is not in the case or the point
/// is not on the body.
Monitor resolve_monitor(const CaseDocument& doc, const FosTable& table);

/// The hold's default length in time scales sqrt(L/g) (docs/fos.md, "The classification").
inline constexpr double kHoldTimeScales = 8.0;

}  // namespace rktsph::fos
