#include "schemes/time_control.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph {

template <int Dim>
void TimeControl<Dim>::start(double initial_strain, double boundary_power, const StepSums<Dim>& sums) {
  initial_strain_ = initial_strain;
  last_power_ = boundary_power;
  const double fb = setup_.function_value(setup_.gravity_function, 0.0);
  for (int d = 0; d < Dim; ++d) last_power_ += fb * setup_.gravity[d] * sums[static_cast<std::size_t>(d)];
  last_damping_power_ = damping_at(0.0) * sums[Dim];
  kinetic_peak_ = 0.5 * sums[Dim];
}

template <int Dim>
void TimeControl<Dim>::end_step(const StepSums<Dim>& sums, double boundary_power, double imposed_kinetic,
                                const std::function<std::string()>& diagnosis) {
  const double dt = step_.dt;
  const double t_new = time_ + dt;
  const double fb = setup_.function_value(setup_.gravity_function, t_new);
  double power = boundary_power;
  for (int d = 0; d < Dim; ++d) power += fb * setup_.gravity[d] * sums[static_cast<std::size_t>(d)];
  // Damping switched off once the kinetic energy has decayed (method-notes §4.2 option B).
  const double kinetic = 0.5 * sums[Dim];
  kinetic_peak_ = std::max(kinetic_peak_, kinetic);
  // It must stay below the ratio for damping.kinetic_ratio_hold (an oscillation trough alone,
  // with the energy momentarily in strain, must not end the relaxation).
  if (setup_.damping_until_kinetic_ratio > 0.0 && t_new >= setup_.damping_ratio_from && t_new < damping_off_time_) {
    if (kinetic < setup_.damping_until_kinetic_ratio * kinetic_peak_) {
      if (kinetic_below_since_ < 0.0) kinetic_below_since_ = t_new;
      if (t_new - kinetic_below_since_ >= setup_.damping_ratio_hold) damping_off_time_ = t_new;
    } else {
      kinetic_below_since_ = -1.0;
    }
  }
  const double cd = damping_at(t_new);
  const double damping_power = cd * sums[Dim];
  external_work_ += 0.5 * dt * (last_power_ + power);
  damping_loss_ += 0.5 * dt * (last_damping_power_ + damping_power);
  // Growth guard: an unstable mode grows v^2 faster than the boundary power (~ v) feeds the
  // work, so it trips this long before the values overflow; the factor leaves room for the
  // scheme's own energy error. The kinetic energy the prescribed velocities impose counts: a
  // kinematic load that starts on a body at rest (no load, no initial stress) moves its nodes
  // a step before their reaction has done any work, and the guard otherwise took the round-off
  // of that first step (10^-11 to 10^-7 J) for a growth.
  const double budget = std::abs(external_work_) + initial_energy_ + imposed_kinetic;
  if (kinetic > kEnergyGrowthLimit * budget && steps_ > 0) {
    throw SolverError(fmt::format(
        "the kinetic energy ({:.3g} J) exceeds {:g} times the work done on the body plus its initial energy and "
        "the kinetic energy of its prescribed velocities ({:.3g} J) at step {} (t = {:.6g} s): the run is unstable; "
        "reduce the time step (time.cfl = {:.3g}) or check the loads, the boundary conditions and the solver "
        "options{}",
        kinetic, kEnergyGrowthLimit, budget, steps_ + 1, t_new, step_.courant, diagnosis ? diagnosis() : ""));
  }
  last_power_ = power;
  last_damping_power_ = damping_power;
  time_ = t_new;
  ++steps_;
}

template <int Dim>
void TimeControl<Dim>::save(io::StateArchive& a) const {
  a.put("clock/time", time_);
  a.put_integer("clock/steps", steps_);
  a.put("clock/dt", step_.dt);
  a.put("clock/dt_initial", initial_dt_);
  a.put("clock/dt_min", dt_min_);
  a.put("clock/dt_max", dt_max_);
  a.put("clock/external_work", external_work_);
  a.put("clock/damping_loss", damping_loss_);
  a.put("clock/initial_strain", initial_strain_);
  a.put("clock/last_power", last_power_);
  a.put("clock/last_damping_power", last_damping_power_);
  a.put("clock/initial_energy", initial_energy_);
  a.put("clock/kinetic_peak", kinetic_peak_);
  a.put("clock/damping_off_time", damping_off_time_);
  a.put("clock/kinetic_below_since", kinetic_below_since_);
}

template <int Dim>
void TimeControl<Dim>::load(const io::StateArchive& a) {
  // The case's step (a checkpoint of a build before time.dt_rule holds only the fixed one).
  const double saved_initial = a.has("clock/dt_initial") ? a.number("clock/dt_initial") : a.number("clock/dt");
  if (saved_initial != initial_dt_) {
    throw InputError(fmt::format("the checkpoint's time step ({:.17g} s) is not this case's ({:.17g} s): the case "
                                 "changed since it was written",
                                 saved_initial, initial_dt_));
  }
  if (setup_.dt_from_current_state) {
    step_.dt = a.number("clock/dt");
    dt_min_ = a.has("clock/dt_min") ? a.number("clock/dt_min") : step_.dt;
    dt_max_ = a.has("clock/dt_max") ? a.number("clock/dt_max") : step_.dt;
  } else if (a.number("clock/dt") != initial_dt_) {
    throw InputError(
        "the checkpoint was written with a step from the current state (time.dt_rule = \"current\"), this case "
        "has a fixed step: give time.dt_rule = \"current\" to resume it");
  }
  time_ = a.number("clock/time");
  steps_ = static_cast<long>(a.integer("clock/steps"));
  external_work_ = a.number("clock/external_work");
  damping_loss_ = a.number("clock/damping_loss");
  initial_strain_ = a.number("clock/initial_strain");
  last_power_ = a.number("clock/last_power");
  last_damping_power_ = a.number("clock/last_damping_power");
  initial_energy_ = a.number("clock/initial_energy");
  kinetic_peak_ = a.number("clock/kinetic_peak");
  damping_off_time_ = a.number("clock/damping_off_time");
  kinetic_below_since_ = a.number("clock/kinetic_below_since");
}

template class TimeControl<1>;
template class TimeControl<2>;
template class TimeControl<3>;

}  // namespace rktsph
