#pragma once
// The time-control room of a run (docs/architecture.md): the clock and the step, the damping
// schedule (method-notes §4.2), the energy account and the growth guard that stops an unstable
// run while its state is still finite.
#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <string>

#include "case/case_setup.hpp"
#include "io/state_archive.hpp"
#include "schemes/time_step.hpp"

namespace rktsph {

struct EnergyBalance {
  double kinetic = 0.0;         // J (per unit thickness in 2D, per unit area in 1D)
  /// The stress points' kinetic energy, 1/2 sum m_E |v_E|^2 at t^{n+1/2}, J: they do not carry
  /// the steady nodal velocity of a body at rest under a load edge (method-notes §5.1,
  /// "Displacements"), so it tells a body at rest from one still moving (`fos.kinetic`).
  double kinetic_stress_points = 0.0;
  double strain = 0.0;          // stored energy: elastic 1/2 sigma : C^-1 : sigma (+ fluid storage in V3), J
  double external_work = 0.0;   // work of boundary tractions and body forces since t = 0, J
  double damping_loss = 0.0;    // energy removed by the velocity damping, J
  double initial_strain = 0.0;  // stored energy of the initial state, J
  /// The nodes' plastic dissipation since t = 0, J: the stored energy the viscoplastic source
  /// removed from the nodal stress (method-notes eq. (5.1.3)).
  double plastic_dissipation = 0.0;
  /// The energy V2's hourglass control removed from the nodal velocity and stress since t = 0, J
  /// (method-notes §2.6; 0 without it).
  double stabilisation_loss = 0.0;
  /// kinetic + strain - initial strain - external work + damping loss + plastic dissipation +
  /// stabilisation loss: zero for an exact account, so it measures the discretisation's error.
  double imbalance() const {
    return kinetic + strain - initial_strain - external_work + damping_loss + plastic_dissipation + stabilisation_loss;
  }
};

/// What the end of a step needs from the particles: momentum (Dim), sum m v^2, a flag set when a
/// velocity is not finite, and the number of nodes faster than the step resolves (|v| dt > dx).
/// Summed by one deterministic reduction (core/execution.hpp).
template <int Dim>
using StepSums = std::array<double, Dim + 3>;

template <int Dim>
class TimeControl {
 public:
  TimeControl(const CaseSetup<Dim>& setup, const TimeStep& step)
      : setup_(setup), step_(step), initial_dt_(step.dt), dt_min_(step.dt), dt_max_(step.dt) {}

  double time() const { return time_; }
  double dt() const { return step_.dt; }
  double courant() const { return step_.courant; }
  double wave_speed() const { return step_.wave_speed; }
  long steps() const { return steps_; }
  /// The step of the case's initial state (time.dt, or C dx / c), s.
  double initial_dt() const { return initial_dt_; }
  /// The shortest and the longest step the rule has given so far (time.dt_rule = "current";
  /// the last step, cut to end on time.end, not counted), s.
  double dt_min() const { return dt_min_; }
  double dt_max() const { return dt_max_; }
  /// The length of the next step (time.dt_rule = "current": set before each step), and the
  /// rule's step before the cut to time.end.
  void set_dt(double dt, double rule_dt) {
    step_.dt = dt;
    dt_min_ = std::min(dt_min_, rule_dt);
    dt_max_ = std::max(dt_max_, rule_dt);
  }

  /// Damping coefficient in force at time t: c_d before damping.until and before the
  /// kinetic-energy switch (damping.until_kinetic_ratio) has fired, else 0.
  double damping_at(double t) const {
    return (t < setup_.damping_until && t < damping_off_time_) ? setup_.damping : 0.0;
  }
  /// Time at which the kinetic-energy switch turned the damping off (infinity if it has not).
  double damping_off_time() const { return damping_off_time_; }
  double peak_kinetic_energy() const { return kinetic_peak_; }
  double external_work() const { return external_work_; }
  double damping_loss() const { return damping_loss_; }
  double initial_strain() const { return initial_strain_; }

  /// The state at t = 0: its stored energy, the power of the loads and sum m v^2.
  void start(double initial_strain, double boundary_power, const StepSums<Dim>& sums);
  /// Before the first step: the energy the body starts with, for the growth guard (taken then,
  /// not at set-up, so that a state set by the caller counts).
  void set_initial_energy(double energy) { initial_energy_ = energy; }
  /// After the stages of a step: account the energies, update the damping switch, check the
  /// growth guard (throws SolverError with what `diagnosis` returns appended; it is called only
  /// then) and advance the clock. `imposed_kinetic` is the kinetic energy of the prescribed
  /// velocity components, which the guard's budget includes.
  void end_step(const StepSums<Dim>& sums, double boundary_power, double imposed_kinetic,
                const std::function<std::string()>& diagnosis);

  /// Checkpoints: every value the clock carries (the step length is the case's).
  void save(io::StateArchive& archive) const;
  void load(const io::StateArchive& archive);

  /// The kinetic energy of a stable run cannot exceed this multiple of the work done on the
  /// body plus its initial energy plus the kinetic energy its prescribed velocities impose (the
  /// materials only dissipate).
  static constexpr double kEnergyGrowthLimit = 100.0;

 private:
  const CaseSetup<Dim>& setup_;
  TimeStep step_;
  double initial_dt_, dt_min_, dt_max_;
  double time_ = 0.0;
  long steps_ = 0;
  double external_work_ = 0.0, damping_loss_ = 0.0, initial_strain_ = 0.0;
  double last_power_ = 0.0, last_damping_power_ = 0.0;
  double initial_energy_ = 0.0;
  double kinetic_peak_ = 0.0, damping_off_time_ = std::numeric_limits<double>::infinity();
  double kinetic_below_since_ = -1.0;  // since when the kinetic energy is below the ratio, -1 = not
};

}  // namespace rktsph
