#include "app/fos_criterion.hpp"

#include <algorithm>
#include <cmath>

namespace rktsph::fos {

const char* hold_outcome_name(HoldOutcome o) {
  switch (o) {
    case HoldOutcome::stable:
      return "stable";
    case HoldOutcome::collapse:
      return "collapse";
    default:
      return "running";
  }
}

template <int Dim>
HoldCriterion<Dim>::HoldCriterion(const HoldRule& rule, std::span<const double, Dim> direction) : rule_(rule) {
  std::copy(direction.begin(), direction.end(), direction_.begin());
  m_.uc_max = -std::numeric_limits<double>::infinity();
}

template <int Dim>
void HoldCriterion<Dim>::Drift::add(double t, const std::array<double, Dim>& u) {
  if (n == 0.0) u0 = u;
  n += 1.0;
  st += t;
  stt += t * t;
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) {
    su[d] += u[d] - u0[d];
    stu[d] += t * (u[d] - u0[d]);
  }
}

template <int Dim>
double HoldCriterion<Dim>::Drift::speed() const {
  // The least-squares slope of each component: (n sum(t u) - sum(t) sum(u)) / (n sum(t^2) - sum(t)^2).
  const double det = n * stt - st * st;
  if (!(det > 0.0)) return 0.0;
  double s = 0.0;
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) {
    const double b = (n * stu[d] - st * su[d]) / det;
    s += b * b;
  }
  return std::sqrt(s);
}

template <int Dim>
HoldOutcome HoldCriterion<Dim>::observe(double t, const std::array<double, Dim>& u) {
  if (outcome_ != HoldOutcome::running) return outcome_;
  double uc = 0.0;
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) uc += direction_[d] * u[d];
  m_.uc = uc;
  m_.uc_max = std::max(m_.uc_max, uc);
  // A step lands on the hold's marks to within round-off of the clock.
  const double slack = 1e-9 * std::max(1.0, rule_.end());
  const double mid = rule_.hold_start + 0.5 * rule_.hold;
  if (t >= rule_.hold_start - slack && t < mid - slack) first_.add(t - rule_.hold_start, u);
  if (t >= mid - slack) second_.add(t - mid, u);
  decide(t);
  return outcome_;
}

template <int Dim>
void HoldCriterion<Dim>::decide(double t) {
  const HoldRule& r = rule_;
  m_.large_displacement = m_.uc > r.collapse * r.length;
  const bool at_end = t >= r.end() - 1e-9 * std::max(1.0, r.end());
  if (m_.large_displacement) {
    outcome_ = HoldOutcome::collapse;
  } else if (at_end) {
    // method-notes eq. (10.5): the drift of the second half against the first.
    m_.first_half = first_.speed();
    m_.second_half = second_.speed();
    const double v1 = m_.first_half, v2 = m_.second_half;
    m_.ratio = v1 > 0.0 ? v2 / v1 : (v2 > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
    const bool drifting = v2 * 0.5 * r.hold > r.rest * r.length;
    outcome_ = drifting && v2 >= r.decay * v1 ? HoldOutcome::collapse : HoldOutcome::stable;
  }
  if (outcome_ != HoldOutcome::running) m_.decided_at = t;
}

template class HoldCriterion<1>;
template class HoldCriterion<2>;
template class HoldCriterion<3>;

}  // namespace rktsph::fos
