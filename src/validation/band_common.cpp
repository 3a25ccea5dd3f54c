#include "validation/band_common.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "core/error.hpp"

namespace rktsph::validation {

HistoryView node_history(const Simulation<2>& solver, const std::string& name, const std::string& who) {
  if (solver.history_layout().find(name) < 0) throw SolverError(who + ": the material carries no " + name);
  return solver.node_history(name);
}

std::vector<char> imperfection_nodes(const Simulation<2>& solver) {
  const auto& nodes = solver.nodes();
  const auto nn = static_cast<std::size_t>(nodes.size());
  std::vector<std::size_t> per_material;
  for (std::size_t i = 0; i < nn; ++i) {
    const auto m = static_cast<std::size_t>(nodes.material[i]);
    if (m >= per_material.size()) per_material.resize(m + 1, 0);
    ++per_material[m];
  }
  const auto sample =
      static_cast<int>(std::max_element(per_material.begin(), per_material.end()) - per_material.begin());
  std::vector<char> seed(nn, 0);
  for (std::size_t i = 0; i < nn; ++i) seed[i] = nodes.material[i] != sample;
  return seed;
}

namespace {

// Principal axis (angle to the horizontal, degrees) of the nodes selected by `keep`, and the
// distance of the point (xi, yi) from that axis.
template <class Keep>
std::pair<double, double> principal_axis(const std::vector<double>& x, const std::vector<double>& y, Keep&& keep,
                                         double xi, double yi, int& count) {
  double mx = 0.0, my = 0.0;
  count = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!keep(i)) continue;
    mx += x[i];
    my += y[i];
    ++count;
  }
  if (count < 2) return {NAN, NAN};
  mx /= count;
  my /= count;
  double cxx = 0.0, cyy = 0.0, cxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!keep(i)) continue;
    cxx += (x[i] - mx) * (x[i] - mx);
    cyy += (y[i] - my) * (y[i] - my);
    cxy += (x[i] - mx) * (y[i] - my);
  }
  const double theta = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);  // major axis, (-90, 90] deg
  const double ux = std::cos(theta), uy = std::sin(theta);
  return {std::abs(theta) * 180.0 / std::numbers::pi, std::abs((xi - mx) * uy - (yi - my) * ux)};
}

}  // namespace

BandFit fit_band(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& eps,
                 double height, double margin, double xi, double yi, const std::vector<char>& outside) {
  BandFit r;
  auto inside = [&](std::size_t i) {
    return y[i] > margin + 1e-9 && y[i] < height - margin - 1e-9 && (outside.empty() || outside[i] == 0);
  };
  double emax = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (inside(i)) emax = std::max(emax, eps[i]);
  }
  r.in_band.assign(x.size(), 0);
  for (std::size_t i = 0; i < x.size(); ++i) r.in_band[i] = inside(i) && emax > 0.0 && eps[i] >= 0.5 * emax;
  auto in_band = [&](std::size_t i) { return r.in_band[i] != 0; };
  int n = 0;
  const auto whole = principal_axis(x, y, in_band, xi, yi, n);
  r.particles = n;
  r.whole = whole.first;
  double ybar = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (in_band(i)) ybar += y[i] / n;
  }
  int nu = 0, nl = 0;
  const auto upper = principal_axis(
      x, y, [&](std::size_t i) { return in_band(i) && y[i] >= ybar; }, xi, yi, nu);
  const auto lower = principal_axis(
      x, y, [&](std::size_t i) { return in_band(i) && y[i] < ybar; }, xi, yi, nl);
  r.upper = upper.first;
  r.lower = lower.first;
  r.offset = std::min(upper.second, lower.second);
  // A pair when both arms are inclined alike and the whole cloud is not (a single straight
  // band gives the same axis for its halves and for the whole).
  r.pair = std::abs(upper.first - whole.first) > 10.0 && std::abs(upper.first - lower.first) < 15.0;
  r.angle = r.pair ? 0.5 * (upper.first + lower.first) : whole.first;
  return r;
}

double band_contrast(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& deps,
                     double xc, double yc) {
  double on = 0.0, off = 0.0;
  int n_on = 0, n_off = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double dx = x[i] - xc, dy = y[i] - yc, r = std::hypot(dx, dy);
    if (r <= 0.15 || r >= 0.45) continue;
    const double to_diagonal = std::min(std::abs(dx - dy), std::abs(dx + dy)) / std::numbers::sqrt2;
    if (to_diagonal < 0.1) on += deps[i], ++n_on;
    if (to_diagonal > 0.2) off += deps[i], ++n_off;
  }
  if (n_on == 0 || n_off == 0 || !(off > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (on / n_on) / (off / n_off);
}

}  // namespace rktsph::validation
