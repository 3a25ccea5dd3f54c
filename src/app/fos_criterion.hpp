#pragma once
// The classification of a strength-reduction trial of `rktsph fos` (docs/fos.md, "The
// classification"; method-notes eq. (10.5)): does the motion of the monitored point die out over
// the hold that follows the case's own run, or does it go on?
//
// The case runs to its time.end t_L (its loads applied and settled, as `rktsph run` would), then
// the hold, h seconds more. Over each half of the hold the monitored node's drift velocity is the
// least-squares slope of its displacement vector u(t) (every step; a ringing whose period is
// short beside h/2 averages out):
//
//   v1 = |du/dt| over [t_L, t_L + h/2],   v2 = |du/dt| over [t_L + h/2, t_L + h].
//
// The trial collapses if its monitored displacement u_c = u . direction exceeds the collapse
// displacement (0.05 L) at any time, or if the node drifts over the second half (v2 h/2 > rest L)
// and as fast as over the first half within the factor `decay` (v2 >= decay v1): the motion does
// not die out. Otherwise it stands. In V1 a standing slope's creep decays as t^-p, with p falling
// continuously as F nears the limit (docs/fos.md, "Why this rule"): `decay` close to 1 calls a
// trial failing only where the drift is steady or growing.
#include <array>
#include <limits>
#include <span>

namespace rktsph::fos {

/// The constants of the rule (docs/fos.md gives the measurements behind them).
struct HoldRule {
  double hold_start = 0.0;  // s: t_L, the case's time.end
  double hold = 1.0;        // s: h
  double length = 1.0;      // m: L
  /// The least ratio v2 / v1 of a motion that does not die out: over a hold of 8 sqrt(L/g) after
  /// 8 s, 0.95 is a creep decaying as t^-0.1 (docs/fos.md).
  double decay = 0.95;
  /// A drift over the second half below rest * L is rest, whatever the ratio (the round-off of a
  /// body at rest: 1e-6 L on the slopes measured).
  double rest = 1e-5;
  /// u_c beyond this fraction of L is a collapse (CASES.md §1.3's 0.05 L).
  double collapse = 0.05;
  double end() const { return hold_start + hold; }
};

enum class HoldOutcome { running, stable, collapse };
const char* hold_outcome_name(HoldOutcome o);

/// What a trial measured (fos.json's trial entries).
struct HoldMeasures {
  double first_half = 0.0;   // m/s: v1
  double second_half = 0.0;  // m/s: v2
  /// v2 / v1 (infinity when only the second half drifts, 0 when neither does).
  double ratio = std::numeric_limits<double>::quiet_NaN();
  double uc = 0.0;      // m: the monitored displacement u . direction, the latest
  double uc_max = 0.0;  // m: its largest value
  bool large_displacement = false;  // u_c > collapse L
  double decided_at = std::numeric_limits<double>::quiet_NaN();  // s: when the outcome was known
};

/// Follows one trial step by step (no allocation) and decides it by the rule above.
template <int Dim>
class HoldCriterion {
 public:
  HoldCriterion(const HoldRule& rule, std::span<const double, Dim> direction);

  /// The monitored node's displacement u at time t, after a step (t increasing). Returns the
  /// outcome so far: running until the hold ends, unless u_c passes the collapse displacement.
  HoldOutcome observe(double t, const std::array<double, Dim>& u);
  HoldOutcome outcome() const { return outcome_; }
  const HoldMeasures& measures() const { return m_; }
  const HoldRule& rule() const { return rule_; }

 private:
  /// Running sums of a least-squares line u_d(t) = a_d + b_d t over one half of the hold, t
  /// counted from the half's start and u from its first value (no cancellation of large sums).
  struct Drift {
    double n = 0.0, st = 0.0, stt = 0.0;
    std::array<double, Dim> u0{}, su{}, stu{};
    void add(double t, const std::array<double, Dim>& u);
    double speed() const;  // |b|, m/s
  };
  void decide(double t);
  HoldRule rule_;
  std::array<double, Dim> direction_{};
  Drift first_, second_;
  HoldOutcome outcome_ = HoldOutcome::running;
  HoldMeasures m_;
};

}  // namespace rktsph::fos
