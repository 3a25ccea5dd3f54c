#pragma once
// Shared by the rigid-footing cases 11 and 12 (docs/cases.md Cases 11 and 12), V2: a run of a
// footing case whose first `[[body]]` is the footing, driven down at a prescribed velocity. The
// footing pressure is the body's reaction (bodies.csv, method-notes eq. (4.5.5)) over the loaded
// width; the maps are taken at given settlements.
#include <string>
#include <vector>

namespace rktsph::validation {

struct FootingRecord {
  double t = 0.0;
  double settlement = 0.0;  // m, -u_y of the footing
  double force = 0.0;       // N/m, the soil's reaction on the footing, +y
  double shear = 0.0;       // N/m, its x component
  double width = 0.0;       // m, the contact width
  double pressure = 0.0;    // Pa, force / loaded width
  double cut = 0.0;         // Pa: the section cut at the cut depth (method-notes §4.5), / loaded width
  long contact_nodes = 0;
  long projections = 0;  // nodes and stress points that crossed the footing so far
};

/// The state at one settlement: per node its reference and current position, displacement,
/// velocity and eps_vp_eq; per stress point its current position and whether it flows
/// (q > sigma_Y, Perzyna overstress > 0).
struct FootingMap {
  double t = 0.0, settlement = 0.0;
  std::vector<double> X, Y, x, y, ux, uy, vx, vy, eps;
  std::vector<double> sx, sy;
  std::vector<char> flowing;
};

struct FootingRun {
  std::vector<FootingRecord> records;
  std::vector<FootingMap> maps;  // at the settlements asked for, in order (those reached)
  double dx = 0.0, t_end = 0.0, t_reached = 0.0;
  std::string stopped;  // the solver's diagnosis if it stopped early
  long steps = 0;
  double seconds = 0.0;
  double min_gap = 0.0;  // m: the most negative gap of a node before projection over the run
};

/// Run `case_file` with `overrides` to time `t_end`, recording the footing (body 0) every
/// `record_every` seconds; the footing pressure is its reaction over `loaded_width`; maps at
/// the settlements `map_settlements` (m, increasing). `yield_stress` (sigma_Y = sqrt(3) c) marks
/// the flowing stress points.
/// `cut_y` is the reference height of a horizontal section across the whole block whose force,
/// -sum sigma_yy V / dx over the row of stress points nearest it (by reference position; current
/// volumes and stress), is recorded beside the reaction as a cross-check: in quasi-static
/// equilibrium without gravity it carries the footing's load.
FootingRun run_footing(const std::string& case_file, const std::vector<std::string>& overrides, double t_end,
                       double record_every, double loaded_width, double yield_stress,
                       const std::vector<double>& map_settlements, double cut_y);

/// Mean of the section-cut pressure over the records with settlement in [s0, s1], Pa.
double mean_cut_pressure(const FootingRun& r, double s0, double s1);

/// Mean footing pressure over the records with settlement in [s0, s1], Pa (NaN if none).
double mean_pressure(const FootingRun& r, double s0, double s1);

void write_footing_records(const std::string& file, const FootingRun& r);
/// One row per node and map: map index, settlement and the node fields.
void write_footing_maps(const std::string& file, const FootingRun& r);

}  // namespace rktsph::validation
