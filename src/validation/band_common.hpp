#pragma once
// Shared by the sample-localisation cases 3 and 16 (docs/cases.md Cases 3 and 16): the band angle of
// docs/cases.md §1.3 from a nodal plastic-strain field.
#include <cstddef>
#include <string>
#include <vector>

#include "schemes/simulation.hpp"

namespace rktsph::validation {

/// The plane-strain sample and platen loading of docs/cases.md Case 3, which Case 16 reuses: 1 m x
/// 2 m, the top platen driven down at 0.1 m/s reached by a linear ramp over 0.1 s.
constexpr double kSampleHeight = 2.0, kSampleWidth = 1.0;
constexpr double kPlatenRampTime = 0.1, kPlatenSpeed = 0.1;

/// Axial strain of the platen at time t.
inline double platen_strain(double t) {
  const double u = t <= kPlatenRampTime ? 0.5 * kPlatenSpeed * t * t / kPlatenRampTime
                                        : 0.5 * kPlatenSpeed * kPlatenRampTime + kPlatenSpeed * (t - kPlatenRampTime);
  return u / kSampleHeight;
}

/// Time at which the platen reaches the axial strain `strain` (past the ramp).
inline double platen_time(double strain) {
  return kPlatenRampTime + (strain * kSampleHeight - 0.5 * kPlatenSpeed * kPlatenRampTime) / kPlatenSpeed;
}

/// A nodal history variable by name (e.g. "eps_vp_eq"); throws SolverError naming `who` if the
/// materials carry no such variable.
HistoryView node_history(const Simulation<2>& solver, const std::string& name, const std::string& who);

/// The imperfection of the sample cases: the nodes of a material other than the sample's (the
/// most common one), 1 per node.
std::vector<char> imperfection_nodes(const Simulation<2>& solver);

/// The band fitted to the cloud of nodes where eps >= 50 % of its maximum inside the band
/// region (docs/cases.md §1.3).
struct BandFit {
  double angle = 0.0;         // degrees to the horizontal: the pair's mean arm angle, or the whole cloud's axis
  double whole = 0.0;         // principal axis of the whole cloud, degrees
  double upper = 0.0;         // principal axis of the part of the cloud above its centroid, degrees
  double lower = 0.0;         // ... below its centroid
  double offset = 0.0;        // distance of the imperfection centre from the nearer arm's axis, m
  bool pair = false;          // a conjugate pair ("<" or ">") rather than one straight band
  int particles = 0;          // nodes in the cloud
  std::vector<char> in_band;  // per node: in the cloud
};

/// Band of the nodal field `eps` at positions (x, y). The band region is the sample without
/// the `margin` next to each platen (y = 0 and y = height) and without the nodes flagged in
/// `outside` (the imperfection; empty: none): the platen corners concentrate strain by the
/// boundary, the imperfection by its weaker material, neither by the band. A conjugate pair is fitted arm by arm, the
/// arms being the parts of the cloud above and below its centroid; the whole-cloud axis is also given. (xi, yi) is the
/// imperfection centre.
BandFit fit_band(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& eps,
                 double height, double margin, double xi, double yi, const std::vector<char>& outside = {});

/// Whether a zone of plastic strain is two crossing 45-degree bands or one diffuse neck (Case 8):
/// the mean increment `deps` of the points within 0.1 m of the two 45-degree diagonals through
/// (xc, yc), over that of the points more than 0.2 m from both, all at 0.15-0.45 m from the
/// centre (inside a 1 m bar's half width). Two bands give a ratio well above 1, a diffuse zone
/// about 1 (though the diagonal fit of its quadrants reads 45 degrees when the zone is as wide
/// as the bar). NaN when either set is empty.
double band_contrast(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& deps,
                     double xc, double yc);

}  // namespace rktsph::validation
