#pragma once
// Rigid bodies in the small-deformation schemes V1 and V3 (2D, method-notes §4.6): a plate or
// footing that lies on a face of the lattice, normal to an axis. The particles do not move in
// these schemes, so the nodes on the body are found once: they share its velocity along its
// normal (smooth) or in full (rough, bonded), which the nodal constraints impose at every
// ApplyConstraints (bc/constraints.hpp, a constraint whose value is the body's velocity). The
// contact is permanent: a small-deformation plate does not separate.
//
// A prescribed axis follows its time function. A force-driven axis follows the force balance
//   M dV/dt = F_applied(t^{n+1/2}) + F_R^{n+1} - c_d M V,   F_R = sum_I sigma_I n A_I   (4.6.1)
// with the total stress at t^{n+1} of the nodes on the body and their tributary lengths A_I.
// In V1 F_R is explicit (stable for dt^2 K / M < 4, K ~ 2 E W / dx, as in V2). In V3 the
// effective-stress part is explicit and the pore-pressure part is implicit: the plate's
// velocity is eliminated from the storage equation (schemes/pressure_stage.cpp, eq. (4.6.3)),
// because an explicit p_w on a plate over a stiff pore fluid would need a plate of many times
// the soil's mass to be stable.
#include <array>
#include <string>
#include <vector>

#include "bodies/contact.hpp"
#include "bodies/rigid_body.hpp"
#include "core/types.hpp"
#include "particles/field.hpp"

namespace rktsph {
namespace io {
class StateArchive;
}

class RigidPlates {
 public:
  static constexpr int NS = 4;  // 2D stress slots: xx, yy, zz, xy
  using FunctionValue = RigidContact::FunctionValue;

  struct Plate {
    BodySpec spec;
    int normal_axis = 1;              // the axis the body's normal lies along
    Vec<2> normal = Vec<2>::Zero();   // unit normal into the soil
    std::vector<Index> nodes;         // the nodes on the body, ascending
    std::vector<double> length;       // their tributary lengths A_I on the body, m
    bool full = false;                // rough / bonded: both components held
    BodyState state;                  // velocity: V^n, then V^{n+1} once drive() has run
    Vec<2> velocity_begin = Vec<2>::Zero();
    Vec<2> applied = Vec<2>::Zero();  // F_applied(t^{n+1/2}) on the force-driven axes, N/m
  };

  /// The bodies of a case on the nodes at `positions` (spacing dx). `faces[i]`: the lattice's
  /// face bits of node i (bit 2d: on the -e_d face, 2d + 1: on the +e_d face), where its face
  /// segment ends. Throws InputError naming the body when it is not normal to an axis, is a polyline,
  /// has a Coulomb law or lies on no node.
  RigidPlates(const std::vector<BodySpec>& specs, const std::vector<Vec<2>>& positions,
              const std::vector<std::uint8_t>& faces, double dx, FunctionValue functions, const std::string& file);

  const std::vector<Plate>& plates() const { return plates_; }
  std::size_t size() const { return plates_.size(); }
  /// Body b's velocity: V^n until drive(), then V^{n+1} (in V3 its pressure-free part V* until
  /// the pressure stage has called add_pressure_velocity()).
  const Vec<2>& velocity(std::size_t b) const { return plates_[b].state.velocity; }
  /// Component d of body b's velocity at time t as the constraints take it: a prescribed axis
  /// its time function at t, a force-driven one the current velocity() (V^n during steps 1 and
  /// 2, V^{n+1} after drive()).
  double velocity_at(std::size_t b, int d, double t) const {
    const Plate& p = plates_[b];
    const auto du = static_cast<std::size_t>(d);
    return p.spec.force_driven[du] ? p.state.velocity[d] : p.spec.velocity[du] * functions_(p.spec.velocity_function[du], t);
  }
  bool any_force() const;

  /// Step of the bodies from t to t + dt with the stress `s` at t^{n+1} (effective in V3, whose
  /// pore-pressure part the pressure stage adds): V^{n+1} on every axis.
  void drive(double t, double dt, double damping, ConstFieldView<double, NS> s);
  /// V3: add to force-driven axis d of body b the velocity dV of the pore pressure, eq. (4.6.3).
  void add_pressure_velocity(std::size_t b, int d, double dv) { plates_[b].state.velocity[d] += dv; }
  /// End of the step: the offsets (trapezoidal in V), the reaction with the total stress at
  /// t^{n+1} (`pore_pressure` null in V1) and its work.
  void finish(double dt, ConstFieldView<double, NS> s, const double* pore_pressure);
  /// The reaction at the current state (t = 0).
  void measure(ConstFieldView<double, NS> s, const double* pore_pressure);

  /// Power of the bodies' reactions on the bodies at the last measure, W/m: sum F_R . V.
  double power() const;

  void save(io::StateArchive& archive, const std::string& prefix) const;
  void load(const io::StateArchive& archive, const std::string& prefix);

 private:
  std::vector<Plate> plates_;
  FunctionValue functions_;
};

}  // namespace rktsph
