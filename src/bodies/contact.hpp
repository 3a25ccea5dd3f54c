#pragma once
// The contact of the nodes with rigid bodies (method-notes §4.5), a node-level kinematic
// constraint in the body's local frame (n into the soil, t = (n_y, -n_x)); no dummy particles,
// no penalty. Per step:
//   begin_step (state at t^n): the bodies' velocities over the step (prescribed, or from the
//     force balance for a force-driven body), and the contact set: nodes within the join
//     distance of a body that approach it (or rest on it), kept while within the keep distance
//     and not under tension beyond the adhesion (never released when bonded); at most two
//     bodies per node;
//   end_step (state at t^{n+1}, after step 2): the constraints on the contact nodes
//     (v_n = V.n; tangential by the law, with Coulomb's stick/slip decided explicitly on the
//     trial stress), the positions and displacements moved with the body, the stress
//     conditions (smooth: sigma_nt = 0; Coulomb slip: sigma_nt = sgn(dv_t) tau_max; at a free
//     corner, the end of a patch where the soil ends, sigma_tt = 0), then any
//     other node or stress point that crossed a body projected back onto it (counted), and the
//     reaction of each body F = sum_I sigma_I n A_I with the tributary lengths A_I.
// Every array is sized at construction: the steps allocate nothing.
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bodies/rigid_body.hpp"
#include "particles/field.hpp"

namespace rktsph {
namespace io {
class StateArchive;
}

/// What the bodies' state is at the last measure (reaction at the current state).
struct BodyState {
  Vec<2> offset = Vec<2>::Zero();    // m, translation from the case's position
  Vec<2> velocity = Vec<2>::Zero();  // m/s
  Vec<2> force = Vec<2>::Zero();     // N/m: the reaction of the soil on the body, sum sigma n A
  double width = 0.0;                // m: the contact width, sum A
  long contact_nodes = 0;
  long node_projections = 0;  // nodes that crossed the body and were put back on it (total)
  long stress_point_projections = 0;
  long free_corners = 0;  // contact nodes where a free face of the soil meets the body (last step)
  double work = 0.0;      // J/m: the work of the reaction on the body, int F.V dt
  double min_gap = 0.0;   // m: the smallest signed distance of a node before projection (last step)
};

/// One contact node of a body at the last measure (the contact pressure profile, contact.csv).
struct ContactPoint {
  int body = 0;
  Index node = 0;
  double s = 0.0;                  // m, its position along the body
  Vec<2> x = Vec<2>::Zero();       // m
  Vec<2> normal = Vec<2>::Zero();  // the body's unit normal there, into the soil
  double width = 0.0;              // m, its tributary length A_I
  // Pa: n.(sigma n) and t.(sigma n) (t the body's tangent, along increasing s), with sigma n the
  // traction the reaction integrates (its end lengths take the mean of the patch's last two
  // nodes), so that the sum of (normal_stress n + shear_stress t) width is the body's force.
  // Tension positive: the contact pressure is -normal_stress.
  double normal_stress = 0.0;
  double shear_stress = 0.0;
};

class RigidContact {
 public:
  static constexpr int kMaxContacts = 2;
  static constexpr int NS = 4;  // 2D stress slots: xx, yy, zz, xy
  using FunctionValue = std::function<double(int, double)>;

  /// Bodies of a case, for `nodes` nodes and `stress_points` stress points at spacing dx.
  RigidContact(const std::vector<BodySpec>& specs, std::size_t nodes, std::size_t stress_points, double dx,
               FunctionValue functions);

  /// The join distance: a node at most this far from a body (as generated on it, or put back
  /// on it by a projection) may come into contact, m.
  double join_distance() const { return join_; }
  /// The keep distance: a contact node stays in contact while at most this far from its body, m.
  double keep_distance() const { return keep_; }

  /// State at t^n: the bodies' velocities over [t, t + dt] and the contact set.
  void begin_step(double t, double dt, double damping, const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v,
                  ConstFieldView<double, NS> s);
  /// State at t^{n+1}: a force-driven body's velocity, the constraints, projections and the
  /// reaction.
  void end_step(double dt, std::vector<Vec<2>>& x, FieldView<double, 2> v, FieldView<double, NS> s,
                FieldView<double, 2> u, std::vector<Vec<2>>& stress_point_x);
  /// What decides a free corner (method-notes eq. (4.5.8)): the kernel's support radius, within
  /// which a node past a patch's end means that the soil goes on (2.4 dx until set), and which
  /// nodes carry a prescribed component of their own (a lattice condition such as a symmetry
  /// roller), where the end of a patch is not a free corner (none until set).
  void set_free_corner_rule(double support_radius, std::function<bool(Index)> has_prescribed) {
    corner_reach_ = support_radius;
    has_prescribed_ = std::move(has_prescribed);
  }
  /// The contact set and the reaction at the current state without advancing (t = 0, output).
  void select_now(double t, const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s);
  bool selected() const { return selected_; }

  /// Kinetic energy of the velocity components the bodies prescribe on their contact nodes, J/m
  /// (the growth guard's budget): the normal one always, the whole velocity where a contact
  /// sticks; `mass(i)` the node's mass.
  double imposed_kinetic(ConstFieldView<double, 2> v, const std::function<double(Index)>& mass) const;
  /// Power of the bodies' tractions on the soil at the last measure, W/m: sum_I (-sigma_I n A_I).v_I.
  double power() const { return power_; }
  const std::vector<RigidBody>& bodies() const { return bodies_; }
  const std::vector<BodyState>& state() const { return state_; }
  /// The contact nodes of every body at the last measure, by body and along it.
  const std::vector<ContactPoint>& profile() const { return profile_; }
  /// 1 at the nodes in contact (excluded from free-surface detection).
  const std::vector<std::uint8_t>& in_contact() const { return in_contact_; }
  /// Contact slots of node i: body index (or -1), normal, Coulomb slip sign (0: stick).
  int contact_body(std::size_t i, int k) const { return body_[kMaxContacts * i + static_cast<std::size_t>(k)]; }
  std::int8_t slip(std::size_t i, int k) const { return slip_[kMaxContacts * i + static_cast<std::size_t>(k)]; }
  const Vec<2>& contact_normal(std::size_t i, int k) const {
    return normal_[kMaxContacts * i + static_cast<std::size_t>(k)];
  }
  /// Body b's velocity at t^{n+1/2} over the current step (a force-driven axis: V^n until step 2).
  const Vec<2>& velocity_half(std::size_t b) const { return velocity_half_[b]; }
  /// The body that a free-surface flag at x with outward normal n_out may only be the
  /// truncation of the support by: x off its surface (beyond the keep distance) but within
  /// `range` of it, and n_out pointing into it (within 45 degrees); -1 if none.
  int faces_body(const Vec<2>& x, const Vec<2>& n_out, double range) const;
  /// The planes of body b's faces that x lies in front of, within `range` (RigidBody::planes_near
  /// at the body's current position and the contact's depth): f(point, normal, distance).
  template <class F>
  void planes_near(std::size_t b, const Vec<2>& x, double range, F&& f) const {
    bodies_[b].planes_near(x, state_[b].offset, depth_, range, std::forward<F>(f));
  }
  /// Whether x lies behind the surface of a body where it is now (re-seeding leaves such cells
  /// empty).
  bool inside(const Vec<2>& x) const;

  /// Follow a reordering of the nodes (node order[k] is now node k): the per-node slots move
  /// with their nodes.
  void reorder_nodes(const std::vector<Index>& order);

  void save(io::StateArchive& archive, const std::string& prefix) const;
  void load(const io::StateArchive& archive, const std::string& prefix);

 private:
  void advance_bodies(double t, double dt, double damping);
  void drive_bodies(double dt, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s);
  void select(const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s);
  void measure(const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s);
  /// along_ <- body b's contact slots within its extent, sorted by their position s along it.
  void sort_along(std::size_t b, const std::vector<Vec<2>>& x);
  void free_corners(const std::vector<Vec<2>>& x, FieldView<double, NS> s);

  std::vector<RigidBody> bodies_;
  std::vector<BodyState> state_;
  std::vector<Vec<2>> velocity_half_, velocity_end_;  // per body, over the current step
  std::vector<Vec<2>> applied_;                       // per body: the applied force at t^{n+1/2}, N/m
  double damping_ = 0.0;                              // c_d over the current step, 1/s
  FunctionValue functions_;
  double dx_, join_, keep_, depth_, adjacent_;
  // Per node: kMaxContacts slots.
  std::vector<int> body_, previous_body_;
  std::vector<Vec<2>> normal_;
  std::vector<std::int8_t> slip_, previous_slip_;
  std::vector<std::uint8_t> in_contact_;
  std::vector<double> release_snn_;  // per slot of the last step: the normal stress that decides a release
  std::vector<Vec<2>> x_begin_;      // positions at t^n (the force-driven balance measures on them)
  std::vector<std::pair<double, std::size_t>> along_;  // (s, node) of one body's contact nodes
  std::vector<ContactPoint> profile_;                  // every body's contact nodes, last measure
  struct PatchEnd {
    std::size_t slot;
    Vec<2> out;   // along the body, away from the patch
    bool beyond;  // a node of the soil lies past it
  };
  std::vector<PatchEnd> ends_;  // single-contact patch ends, current step
  double corner_reach_ = 0.0;   // m, set by the constructor and set_free_corner_rule
  std::function<bool(Index)> has_prescribed_;
  std::vector<double> last_power_;  // per body, F.V at the last measure
  double power_ = 0.0;
  bool selected_ = false;
};

}  // namespace rktsph
