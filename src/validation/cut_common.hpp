#pragma once
// Shared by the vertical-cut validation cases 4-6 (docs/cases.md Cases 4, 5, 6): running a cut case
// with histories of the crest displacement and the kinetic energy, the stable / collapse
// classification of docs/cases.md §1.3, and measures of the plastic-strain field.
#include <functional>
#include <string>
#include <vector>

#include "schemes/simulation.hpp"

namespace rktsph::validation {

/// docs/cases.md §1.3: the outcome of a limit-state run.
enum class CutOutcome { stable, collapse, undecided };
const char* outcome_name(CutOutcome o);

struct Classification {
  CutOutcome outcome = CutOutcome::undecided;
  double uc_end = 0.0;        // crest horizontal displacement at the end, m (outward positive)
  double uc_change = 0.0;     // max - min of u_c over the last window, m
  double ke_ratio = 0.0;      // largest kinetic energy in the last window / peak kinetic energy
  bool accelerating = false;  // u_c still accelerating at the end
};

/// Classify a run from its histories (time t, crest displacement u_c outward positive, kinetic
/// energy ke, all sampled alike) for a cut of height H (docs/cases.md §1.3):
///  stable   if over the last `window` seconds u_c changes by less than 1e-3 H and the
///           kinetic energy stays two orders of magnitude below its peak;
///  collapse if u_c > 0.05 H, or if u_c is still accelerating at the end (its increment over
///           the last half window exceeds that over the half window before by more than 10 %
///           and is larger than 1e-3 H);
///  undecided otherwise.
Classification classify_cut(const std::vector<double>& t, const std::vector<double>& uc, const std::vector<double>& ke,
                            double H, double window = 1.0);

/// Nodal fields of a cut at one time (regular lattice, 2D).
struct CutSnapshot {
  double time = 0.0;
  std::vector<double> x, y, ux, uy, vx, vy, sxx, syy, sxy, eps;
};

struct CutRun {
  double dx = 0.0, width = 0.0, height = 0.0, dt = 0.0;
  std::vector<double> t, uc, uyc, ke;  // histories: crest u_x, crest u_y, kinetic energy (J/m)
  CutSnapshot final_state;
  CutSnapshot onset;  // when u_c first exceeded the onset threshold (if it did)
  bool has_onset = false;
  /// When u_c first exceeded the collapse threshold 0.05 H (docs/cases.md §1.3), if it did: fields
  /// of different runs compared at the same crest displacement.
  CutSnapshot at_collapse;
  bool has_collapse_state = false;
  double damping_off_time = 0.0;  // s, infinity if the kinetic-energy switch never fired
  double peak_ke = 0.0;
  long steps = 0;
  long max_substeps = 0;
  double seconds = 0.0;
  std::string error;  // non-empty if the solver stopped (non-finite state)
  /// Traction residuals at the end: the stress points' stresses extrapolated linearly
  /// from the two stress-point columns (rows) next to the face x = W (the top y = H), largest
  /// |sigma_xx|, |sigma_xy| on the face (|sigma_yy|, |sigma_xy| on the top), Pa. The nodal
  /// values there are prescribed and exact by construction; these are what the body carries.
  double face_residual = 0.0, top_residual = 0.0;
  /// The face residual over the rows y >= 0.1 H only (away from the toe corner), Pa.
  double face_residual_above_toe = 0.0;
  /// The face residual over the rows y >= 2 dx (all but the first two stress-point rows), Pa.
  /// A zone of fixed size in cells, not in metres: next to a singular corner it still grows
  /// as dx^(lambda - 1) (scripts/williams_corner.py), only more weakly than the toe row.
  double face_residual_beyond_2dx = 0.0;
  /// RMS (L2) face residual: sqrt(mean over the stress-point rows of s_n^2 + s_t^2), Pa. Finite
  /// under a corner singularity r^(lambda - 1) with lambda > 1/2, where the maximum is not.
  double face_residual_rms = 0.0;
  /// Per row of stress points next to the face: its height y and the extrapolated face
  /// tractions s_n = sigma_xx, s_t = sigma_xy (Pa), sorted by y (the first is the toe row).
  struct FaceRow {
    double y = 0.0, sn = 0.0, st = 0.0;
  };
  std::vector<FaceRow> face_rows;
  Classification classification;
};

using StepHook = std::function<void(const Simulation<2>&)>;

/// Run a 2D cut case file with --set overrides, recording the histories every `record_dt`
/// seconds (and calling `hook` after every step if given). `onset_uc` (m) > 0 takes a snapshot
/// when u_c first exceeds it. Results are cached by (file, overrides) within the process, so
/// cases sharing a run (6 compares with 5) compute it once; a hook disables the cache.
CutRun run_cut(const std::string& file, const std::vector<std::string>& overrides, double record_dt,
               double onset_uc = 0.0, const StepHook& hook = {});

CutSnapshot snapshot(const Simulation<2>& solver, double time);

/// Value of a nodal field at the lattice node nearest to (x, y).
double at_node(const CutSnapshot& s, const std::vector<double>& field, double x, double y);
/// Bilinear interpolation of a nodal field on the regular lattice of spacing dx.
double bilinear(const CutSnapshot& s, const std::vector<double>& field, double dx, double x, double y);

/// Full width at half maximum of a 1-D profile f(x) around its largest value inside
/// [xlo, xhi] (linear interpolation of the crossings); NaN if it is not bracketed. The peak
/// position is returned in `peak_x`.
double fwhm(const std::vector<double>& x, const std::vector<double>& f, double xlo, double xhi, double& peak_x);

/// Nodes of the row y = y0 (sorted by x) of field f: x and values.
void row_profile(const CutSnapshot& s, const std::vector<double>& field, double y0, double dx, std::vector<double>& xs,
                 std::vector<double>& fs);

/// Smallest distance from the point (px, py) to a node where eps >= 0.5 max(eps) (the band
/// cloud of docs/cases.md §1.3), with the maximum taken over nodes with y >= ymin.
double band_distance_to(const CutSnapshot& s, double px, double py, double ymin);

/// Emergence of the failure surface on the top, m behind the crest: position of the largest
/// eps_vp_eq on the top row away from the crest region (x <= W - 0.3 H). Defined with case 5.
double emergence_behind_crest(const CutSnapshot& s, double dx, double W, double H);

/// Write histories t, u_c, u_y crest, kinetic energy as CSV.
void write_history_csv(const std::string& file, const CutRun& r);
/// Write a snapshot as CSV (x, y, ux, uy, vx, vy, sxx, syy, sxy, eps_vp_eq).
void write_snapshot_csv(const std::string& file, const CutSnapshot& s);

/// The Williams eigenvalue of the Case 4(a) toe, where the rough (clamped) base meets the free
/// face: a right-angled clamped-free wedge in plane strain at nu = 0.3, stresses ~ r^(lambda - 1)
/// (scripts/williams_corner.py).
inline constexpr double kToeWilliamsLambda = 0.7112;

/// The toe-row scaling check of docs/cases.md Case 4(a) (restated criterion): under the corner
/// singularity the toe row's residual grows as dx^(lambda - 1), so residual x dx^(1 - lambda)
/// stays constant over the spacings when the singular field is resolved.
struct ToeScaling {
  std::vector<double> scaled;  // toe-row residual x dx^(1 - lambda), per spacing
  double mean = 0.0;           // of `scaled`
  double max_deviation = 0.0;  // max |scaled / mean - 1|
};
/// From the spacings dx (m) and the toe-row residuals at each (any unit); NaN figures when a
/// residual is not finite or fewer than two spacings are given.
ToeScaling toe_scaling(const std::vector<double>& dx, const std::vector<double>& toe_residual,
                       double lambda = kToeWilliamsLambda);

struct Metric;
/// 0 stable, 1 collapse, 2 undecided (for a reported figure).
double outcome_value(CutOutcome o);
/// Pass/fail metric "classified as expected" (value 1 = yes), with the figures in its name.
Metric outcome_metric(const std::string& name, const CutRun& r, CutOutcome expected);
/// One line describing a run for the report notes.
std::string run_note(const std::string& label, const CutRun& r);

}  // namespace rktsph::validation
