#include "bodies/contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "io/state_archive.hpp"
#include "particles/permutation.hpp"

namespace rktsph {

namespace {

// Join and keep distances in spacings (method-notes §4.5). A node joins when it touches the
// body: as generated on it (g = 0) or put back on it by a projection; a capture band of half a
// spacing would hold an approaching node at the distance where it was caught, a gap under the
// body. Once in contact a node stays while within half a spacing (it is put back on the surface
// every step), so that a node sliding over a polyline's vertex is not lost by round-off.
constexpr double kJoinOverDx = 1e-3;
constexpr double kKeepOverDx = 0.5;
// A segment or polyline is a rigid layer one spacing thick: points further behind it are not
// within it (they belong to no contact with it and are never projected onto it).
constexpr double kDepthOverDx = 1.0;
// Two contact nodes further apart than this along the body are the ends of two patches.
constexpr double kAdjacentOverDx = 2.0;
const double kCos45 = std::sqrt(0.5);

// Whether a contact under `law` with Coulomb slip state `slip` holds the node's tangential motion.
bool sticks(ContactLaw law, std::int8_t slip) {
  return law == ContactLaw::rough || law == ContactLaw::bonded || (law == ContactLaw::coulomb && slip == 0);
}

// sigma n in 2D (slots xx, yy, zz, xy).
Vec<2> traction(const double* s, const Vec<2>& n) {
  return Vec<2>(s[0] * n[0] + s[3] * n[1], s[3] * n[0] + s[1] * n[1]);
}

// Add delta to the shear sigma_nt of the local frame: sigma += delta (n (x) t + t (x) n), which
// leaves sigma_nn and sigma_tt unchanged (method-notes eq. (4.5.4)).
void add_shear(double* s, const Vec<2>& n, const Vec<2>& t, double delta) {
  s[0] += 2.0 * delta * n[0] * t[0];
  s[1] += 2.0 * delta * n[1] * t[1];
  s[3] += delta * (n[0] * t[1] + n[1] * t[0]);
}

}  // namespace

RigidContact::RigidContact(const std::vector<BodySpec>& specs, std::size_t nodes, std::size_t stress_points, double dx,
                           FunctionValue functions)
    : functions_(std::move(functions)),
      dx_(dx),
      join_(kJoinOverDx * dx),
      keep_(kKeepOverDx * dx),
      depth_(kDepthOverDx * dx),
      adjacent_(kAdjacentOverDx * dx) {
  (void)stress_points;
  for (const BodySpec& spec : specs) bodies_.emplace_back(spec);
  state_.resize(bodies_.size());
  velocity_half_.assign(bodies_.size(), Vec<2>::Zero());
  velocity_end_.assign(bodies_.size(), Vec<2>::Zero());
  applied_.assign(bodies_.size(), Vec<2>::Zero());
  last_power_.assign(bodies_.size(), 0.0);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodySpec& spec = bodies_[b].spec();
    for (int d = 0; d < 2; ++d) {
      const auto du = static_cast<std::size_t>(d);
      if (!spec.force_driven[du])
        state_[b].velocity[d] = spec.velocity[du] * functions_(spec.velocity_function[du], 0.0);
    }
  }
  body_.assign(kMaxContacts * nodes, -1);
  previous_body_.assign(kMaxContacts * nodes, -1);
  slip_.assign(kMaxContacts * nodes, 0);
  previous_slip_.assign(kMaxContacts * nodes, 0);
  normal_.assign(kMaxContacts * nodes, Vec<2>::Zero());
  in_contact_.assign(nodes, 0);
  release_snn_.assign(kMaxContacts * nodes, 0.0);
  x_begin_.assign(nodes, Vec<2>::Zero());
  along_.reserve(nodes);
  ends_.reserve(16);
  corner_reach_ = 2.4 * dx;  // the support at the default h = 1.2 dx
}

void RigidContact::advance_bodies(double t, double dt, double damping) {
  // Prescribed axes take V(t^{n+1/2}) for the positions and V(t^{n+1}) for the nodal velocities
  // at the end of the step. A force-driven axis keeps V^n until drive_bodies, after step 2.
  damping_ = damping;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodySpec& spec = bodies_[b].spec();
    for (int d = 0; d < 2; ++d) {
      const auto du = static_cast<std::size_t>(d);
      if (spec.force_driven[du]) {
        applied_[b][d] = spec.force[du] * functions_(spec.force_function[du], t + 0.5 * dt);
        velocity_half_[b][d] = velocity_end_[b][d] = state_[b].velocity[d];
      } else {
        velocity_half_[b][d] = spec.velocity[du] * functions_(spec.velocity_function[du], t + 0.5 * dt);
        velocity_end_[b][d] = spec.velocity[du] * functions_(spec.velocity_function[du], t + dt);
      }
    }
  }
}

void RigidContact::drive_bodies(double dt, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s) {
  // Load control (method-notes eq. (4.5.7)): M dV/dt = F_applied + F_R - c_d M V, with the
  // reaction F_R of the stress at t^{n+1} from step 2 (before the contact conditions change its
  // shear), which step 2 computed with the contact nodes at V^n: the body's velocity then
  // follows its reaction as a symplectic Euler step does its spring, stable for
  // dt sqrt(K/M) < 2 (K ~ 2 E W/dx, the contact layer's stiffness). The reaction at t^n
  // instead lags the body by a step: measured unstable at M = 100 kg/m on a 2000 kg/m block
  // (growing without bound within 160 steps). The acceleration is frozen over the step and
  // integrated exactly with the damping.
  bool any = false;
  for (const RigidBody& body : bodies_) any = any || body.spec().any_force();
  if (!any) return;
  // On the positions of t^n, where the contact set was chosen: step 2 may carry a node stuck
  // at the body's edge a hair past it, and measured there that node would drop out of the sum
  // (its length going to its neighbour's end length), by round-off, step to step — a footing
  // whose edge node had relaxed to sigma_nn ~ 0 was balanced by 10 % more than it reported, and
  // the flips kicked it into a growing vibration (docs/VALIDATION.md, "V2 with a rigid footing").
  measure(x_begin_, v, s);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodySpec& spec = bodies_[b].spec();
    for (int d = 0; d < 2; ++d) {
      if (!spec.force_driven[static_cast<std::size_t>(d)]) continue;
      const double a = (applied_[b][d] + state_[b].force[d]) / spec.mass;
      const double v0 = state_[b].velocity[d];
      double v1 = v0 + a * dt;
      if (damping_ != 0.0) {
        const double decay = -std::expm1(-damping_ * dt);  // 1 - e^{-c_d dt}
        v1 = v0 - decay * v0 + a * decay / damping_;
      }
      velocity_half_[b][d] = 0.5 * (v0 + v1);
      velocity_end_[b][d] = v1;
    }
  }
}

void RigidContact::select(const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s) {
  std::swap(body_, previous_body_);
  std::swap(slip_, previous_slip_);
  const std::size_t nn = x.size();
  // The normal stress that decides whether a contact node of the last step is released: the
  // 1-2-1 mean of sigma_nn with its neighbours in its patch (sorted along the body; the mean
  // of the two at a patch's end), not the node's own. The nodal stress of a row of contact
  // nodes can carry an odd-even mode, whose tensile half released nodes inside a compressed
  // patch, one at a time (a rough footing's pressure jumped by 25 % while the node was out;
  // docs/VALIDATION.md Case 12). A node alone in its patch keeps its own sigma_nn.
  // Only for bodies with release = "patch": on a fixed base under a flowing slide the mean keeps
  // nodes at a patch's end attached that their own tension would release, and thesis Cases 9
  // and 10 went unstable earlier with it (docs/VALIDATION.md).
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    if (!bodies_[b].spec().release_on_patch_mean) continue;
    along_.clear();
    for (std::size_t i = 0; i < nn; ++i) {
      for (int k = 0; k < kMaxContacts; ++k) {
        const std::size_t slot = kMaxContacts * i + static_cast<std::size_t>(k);
        if (previous_body_[slot] != static_cast<int>(b)) continue;
        const BodyGap gap = bodies_[b].gap(x[i], state_[b].offset, depth_);
        const Vec<2>& n = normal_[slot];
        release_snn_[slot] = n.dot(traction(s[static_cast<Index>(i)], n));
        if (gap.within) along_.emplace_back(gap.s, slot);
      }
    }
    std::sort(along_.begin(), along_.end());
    // Own values first (release_snn_ holds them), then the means, from a copy of the neighbours'.
    double before = 0.0;  // the previous node's own value
    for (std::size_t j = 0; j < along_.size(); ++j) {
      const std::size_t slot = along_[j].second;
      const double own = release_snn_[slot];
      const bool has_left = j > 0 && along_[j].first - along_[j - 1].first <= adjacent_;
      const bool has_right = j + 1 < along_.size() && along_[j + 1].first - along_[j].first <= adjacent_;
      const double right = has_right ? release_snn_[along_[j + 1].second] : 0.0;
      if (has_left && has_right) {
        release_snn_[slot] = 0.25 * (before + 2.0 * own + right);
      } else if (has_left) {
        release_snn_[slot] = 0.5 * (before + own);
      } else if (has_right) {
        release_snn_[slot] = 0.5 * (own + right);
      }
      before = own;
    }
  }
  for (std::size_t i = 0; i < nn; ++i) {
    int count = 0;
    const std::size_t base = kMaxContacts * i;
    for (int k = 0; k < kMaxContacts; ++k) {
      body_[base + static_cast<std::size_t>(k)] = -1;
      slip_[base + static_cast<std::size_t>(k)] = 0;
    }
    for (std::size_t b = 0; b < bodies_.size() && count < kMaxContacts; ++b) {
      const BodyGap gap = bodies_[b].gap(x[i], state_[b].offset, depth_);
      if (!gap.within || gap.g > keep_) continue;
      int was = -1;
      for (int k = 0; k < kMaxContacts; ++k) {
        if (previous_body_[base + static_cast<std::size_t>(k)] == static_cast<int>(b)) was = k;
      }
      const BodySpec& spec = bodies_[b].spec();
      const bool bonded = spec.law == ContactLaw::bonded;
      const Vec<2>& n = gap.normal;
      // Separation (method-notes §4.5): a normal stress more tensile than the adhesion releases
      // the node, and keeps a node that touches from joining; bonded contacts never separate.
      const double snn = was >= 0 && spec.release_on_patch_mean ? release_snn_[base + static_cast<std::size_t>(was)]
                                                                : n.dot(traction(s[static_cast<Index>(i)], n));
      const bool holds = bonded || snn <= spec.adhesion;
      bool in = false;
      if (was >= 0) {
        in = holds;
      } else if (gap.g <= join_) {
        const Vec<2> vi(v(static_cast<Index>(i), 0), v(static_cast<Index>(i), 1));
        const double approach = (vi - state_[b].velocity).dot(n);  // < 0: closing
        in = holds && (bonded || approach <= 0.0);
      }
      if (!in) continue;
      const std::size_t slot = base + static_cast<std::size_t>(count++);
      body_[slot] = static_cast<int>(b);
      normal_[slot] = n;
      slip_[slot] = was >= 0 ? previous_slip_[base + static_cast<std::size_t>(was)] : 0;
    }
    in_contact_[i] = count > 0 ? 1 : 0;
    x_begin_[i] = x[i];
  }
  selected_ = true;
}

void RigidContact::begin_step(double t, double dt, double damping, const std::vector<Vec<2>>& x,
                              ConstFieldView<double, 2> v, ConstFieldView<double, NS> s) {
  advance_bodies(t, dt, damping);
  select(x, v, s);
}

void RigidContact::select_now(double t, const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v,
                              ConstFieldView<double, NS> s) {
  (void)t;
  select(x, v, s);
  measure(x, v, s);
  for (std::size_t b = 0; b < bodies_.size(); ++b) last_power_[b] = state_[b].force.dot(state_[b].velocity);
}

void RigidContact::end_step(double dt, std::vector<Vec<2>>& x, FieldView<double, 2> v, FieldView<double, NS> s,
                            FieldView<double, 2> u, std::vector<Vec<2>>& stress_point_x) {
  drive_bodies(dt, ConstFieldView<double, 2>(v.data(), v.size(), 2),
               ConstFieldView<double, NS>(s.data(), s.size(), NS));
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    state_[b].offset += dt * velocity_half_[b];
    state_[b].velocity = velocity_end_[b];
    state_[b].min_gap = std::numeric_limits<double>::infinity();
  }
  const std::size_t nn = x.size();
  for (std::size_t i = 0; i < nn; ++i) {
    const auto ii = static_cast<Index>(i);
    double* vi = v[ii];
    double* si = s[ii];
    double* ui = u[ii];
    auto shift = [&](const Vec<2>& by) {
      x[i] += by;
      ui[0] += by[0];
      ui[1] += by[1];
    };
    if (in_contact_[i] != 0) {
      for (int k = 0; k < kMaxContacts; ++k) {
        const std::size_t slot = kMaxContacts * i + static_cast<std::size_t>(k);
        const int b = body_[slot];
        if (b < 0) continue;
        const auto bu = static_cast<std::size_t>(b);
        const BodySpec& spec = bodies_[bu].spec();
        const Vec<2>& n = normal_[slot];
        const Vec<2> t = body_tangent(n);
        const Vec<2>& v_end = velocity_end_[bu];
        // The tangential law (method-notes eq. (4.5.3), (4.5.4)), on the stress of step 2.
        std::int8_t sl = slip_[slot];
        const Vec<2> tn = traction(si, n);
        const double snn = n.dot(tn), snt = t.dot(tn);
        if (spec.law == ContactLaw::smooth) {
          add_shear(si, n, t, -snt);
        } else if (spec.law == ContactLaw::coulomb) {
          const double tau = spec.adhesion + spec.friction * std::max(-snn, 0.0);
          const double dv_t = (Vec<2>(vi[0], vi[1]) - v_end).dot(t);
          if (sl != 0 && dv_t * sl <= 0.0) sl = 0;                      // the slip stopped or reversed: stick
          if (sl == 0 && std::abs(snt) > tau) sl = snt > 0.0 ? 1 : -1;  // the trial shear exceeds the limit
          if (sl != 0) add_shear(si, n, t, sl * tau - snt);
          slip_[slot] = sl;
        }
        const bool stick = sticks(spec.law, sl);
        // The kinematics: the normal motion (all laws) and, sticking, the tangential motion of the
        // step are the body's (method-notes eq. (4.5.2)).
        const Vec<2> step = x[i] - x_begin_[i] - dt * velocity_half_[bu];
        shift(-step.dot(n) * n);
        if (stick) shift(-step.dot(t) * t);
        const Vec<2> dv = Vec<2>(vi[0], vi[1]) - v_end;
        Vec<2> fix = -dv.dot(n) * n;
        if (stick) fix -= dv.dot(t) * t;
        vi[0] += fix[0];
        vi[1] += fix[1];
        // Back on the surface (round-off, or a polyline turning under a sliding node).
        const BodyGap gap = bodies_[bu].gap(x[i], state_[bu].offset, depth_);
        if (gap.within) shift(-gap.g * gap.normal);
      }
    }
    // Nodes that crossed a body they are not in contact with: put back on it, an inelastic
    // touch-down (the closing normal velocity relative to the body removed), counted.
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      bool touching = false;
      for (int k = 0; k < kMaxContacts; ++k)
        touching = touching || body_[kMaxContacts * i + static_cast<std::size_t>(k)] == static_cast<int>(b);
      if (touching) continue;
      const BodyGap gap = bodies_[b].gap(x[i], state_[b].offset, depth_);
      if (!gap.within) continue;
      state_[b].min_gap = std::min(state_[b].min_gap, gap.g);
      if (gap.g >= 0.0) continue;
      shift(-gap.g * gap.normal);
      const double closing = (Vec<2>(vi[0], vi[1]) - velocity_end_[b]).dot(gap.normal);
      if (closing < 0.0) {
        vi[0] -= closing * gap.normal[0];
        vi[1] -= closing * gap.normal[1];
      }
      ++state_[b].node_projections;
    }
  }
  for (auto& xe : stress_point_x) {
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      const BodyGap gap = bodies_[b].gap(xe, state_[b].offset, depth_);
      if (!gap.within || gap.g >= 0.0) continue;
      xe -= gap.g * gap.normal;
      ++state_[b].stress_point_projections;
    }
  }
  const auto cv = ConstFieldView<double, 2>(v.data(), v.size(), 2);
  const auto cs = ConstFieldView<double, NS>(s.data(), s.size(), NS);
  measure(x, cv, cs);
  // After the reaction, which sigma_tt does not enter (sigma n); measure() found the patch ends.
  free_corners(x, s);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const double p = state_[b].force.dot(state_[b].velocity);
    state_[b].work += 0.5 * dt * (last_power_[b] + p);
    last_power_[b] = p;
  }
}

double RigidContact::imposed_kinetic(ConstFieldView<double, 2> v, const std::function<double(Index)>& mass) const {
  double energy = 0.0;
  for (std::size_t i = 0; i < in_contact_.size(); ++i) {
    if (in_contact_[i] == 0) continue;
    const auto ii = static_cast<Index>(i);
    const Vec<2> vi(v(ii, 0), v(ii, 1));
    double prescribed = 0.0;  // v^2 of the prescribed components, at most |v|^2 (two bodies)
    for (int k = 0; k < kMaxContacts; ++k) {
      const std::size_t slot = kMaxContacts * i + static_cast<std::size_t>(k);
      const int b = body_[slot];
      if (b < 0) continue;
      const double vn = vi.dot(normal_[slot]);
      prescribed += sticks(bodies_[static_cast<std::size_t>(b)].spec().law, slip_[slot]) ? vi.squaredNorm() : vn * vn;
    }
    energy += 0.5 * mass(ii) * std::min(prescribed, vi.squaredNorm());
  }
  return energy;
}

void RigidContact::sort_along(std::size_t b, const std::vector<Vec<2>>& x) {
  along_.clear();
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (in_contact_[i] == 0) continue;
    for (int k = 0; k < kMaxContacts; ++k) {
      const std::size_t slot = kMaxContacts * i + static_cast<std::size_t>(k);
      if (body_[slot] != static_cast<int>(b)) continue;
      const BodyGap gap = bodies_[b].gap(x[i], state_[b].offset, depth_);
      if (gap.within) along_.emplace_back(gap.s, slot);
    }
  }
  std::sort(along_.begin(), along_.end());
}

void RigidContact::free_corners(const std::vector<Vec<2>>& x, FieldView<double, NS> s) {
  // A free corner (method-notes §4.5, eq. (4.5.8)): a contact node at the end of its patch along
  // the body where the soil ends, so that a free face of the soil meets the body there. That
  // face's normal traction vanishes; on a face across the body (normal +-t) it is sigma_tt, which
  // no contact law sets, and which the node otherwise keeps from step 2. Left free, it let a block
  // dragged over a Coulomb base carry 16 % more shear than the friction limit, through the
  // compression that the overturning moment puts at the leading corner (docs/VALIDATION.md,
  // "Rigid bodies"). sigma_nn and sigma_nt stay the contact's. The candidates are the patch ends
  // that measure() found, except a node on two bodies (the face beyond is the other body's) or
  // with a lattice condition (a symmetry plane); not a corner either: a patch end with soil past
  // it within the kernel's support (a footing's edge on a wider surface, or the soil heaved up
  // beside a footing that has sunk into it).
  for (BodyState& st : state_) st.free_corners = 0;
  const std::size_t nn = x.size();
  if (ends_.empty()) return;
  const double past = 0.5 * dx_, reach2 = corner_reach_ * corner_reach_;
  for (std::size_t k = 0; k < nn; ++k) {
    for (PatchEnd& e : ends_) {
      const Vec<2> r = x[k] - x[e.slot / kMaxContacts];
      if (r.dot(e.out) > past && r.squaredNorm() < reach2) e.beyond = true;
    }
  }
  for (const PatchEnd& e : ends_) {
    if (e.beyond) continue;
    double* si = s[static_cast<Index>(e.slot / kMaxContacts)];
    const Vec<2>& t = e.out;
    const double stt = t[0] * t[0] * si[0] + t[1] * t[1] * si[1] + 2.0 * t[0] * t[1] * si[3];
    // sigma -= sigma_tt t (x) t: sigma_nn and sigma_nt are unchanged (n . t = 0).
    si[0] -= stt * t[0] * t[0];
    si[1] -= stt * t[1] * t[1];
    si[3] -= stt * t[0] * t[1];
    ++state_[static_cast<std::size_t>(body_[e.slot])].free_corners;
  }
}

void RigidContact::measure(const std::vector<Vec<2>>& x, ConstFieldView<double, 2> v, ConstFieldView<double, NS> s) {
  // The reaction of the soil on each body, F = sum_I sigma_I n A_I (method-notes eq. (4.5.5)):
  // A_I the tributary length along the body, half the distance to each neighbouring contact
  // node, and at the end of a patch the distance d to the body's edge (the contact ends at the
  // edge, before the next node) when d < dx, or when d < 2 dx and the soil goes on past that edge
  // (a node not in contact with the body lies past it within 2 dx: the patch's last node has slid
  // inwards, as under a smooth footing whose soil flows out past its edge), else nothing (the
  // soil ends at the node: as the half segment of a lattice's corner node). The end length d
  // carries the mean traction of the patch's last two nodes: the nodal stress of a row of
  // contact nodes can carry an odd-even mode, which the half-spacing sum cancels but an end
  // weight on one node alone does not (a footing's pressure jumped by 15-25 % as nodes slid
  // off its edge; docs/VALIDATION.md Case 12).
  power_ = 0.0;
  profile_.clear();
  ends_.clear();
  std::array<bool, 2> beyond{false, false};
  auto edge = [&](double d, std::size_t end) {
    return d >= 0.0 && (d < dx_ || (beyond[end] && d < adjacent_)) ? d : 0.0;
  };
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    beyond = {false, false};
    const BodySpec& spec = bodies_[b].spec();
    if (spec.shape != BodyShape::plane) {
      const std::vector<Vec<2>>& p = spec.points;
      const std::array<Vec<2>, 2> end{p.front() + state_[b].offset, p.back() + state_[b].offset};
      const std::array<Vec<2>, 2> off{p.front() - p[1], p.back() - p[p.size() - 2]};  // pointing off each edge
      for (std::size_t i = 0; i < x.size(); ++i) {
        bool touching = false;
        for (int k = 0; k < kMaxContacts; ++k)
          touching = touching || body_[kMaxContacts * i + static_cast<std::size_t>(k)] == static_cast<int>(b);
        if (touching) continue;
        for (std::size_t e = 0; e < 2; ++e) {
          const Vec<2> r = x[i] - end[e];
          if (r.dot(off[e]) > 0.0 && r.norm() <= adjacent_) beyond[e] = true;
        }
      }
    }
    sort_along(b, x);
    Vec<2> force = Vec<2>::Zero();
    double width = 0.0, power = 0.0;
    const double s0 = bodies_[b].s_begin(), s1 = bodies_[b].s_end();
    auto node_traction = [&](std::size_t j) {
      const std::size_t slot = along_[j].second;
      return traction(s[static_cast<Index>(slot / kMaxContacts)], normal_[slot]);
    };
    for (std::size_t j = 0; j < along_.size(); ++j) {
      const double sj = along_[j].first;
      const bool has_left = j > 0 && sj - along_[j - 1].first <= adjacent_;
      const bool has_right = j + 1 < along_.size() && along_[j + 1].first - sj <= adjacent_;
      const double left = has_left ? 0.5 * (sj - along_[j - 1].first) : edge(sj - s0, 0U);
      const double right = has_right ? 0.5 * (along_[j + 1].first - sj) : edge(s1 - sj, 1U);
      const std::size_t slot = along_[j].second;
      const auto i = static_cast<Index>(slot / kMaxContacts);
      const Vec<2> t = node_traction(j);
      // A patch end: a candidate free corner (free_corners()) unless on two bodies or held by a
      // lattice condition.
      const std::size_t iu = slot / kMaxContacts;
      if ((!has_left || !has_right) && (body_[kMaxContacts * iu] < 0 || body_[kMaxContacts * iu + 1] < 0) &&
          !(has_prescribed_ && has_prescribed_(i))) {
        const Vec<2> along = body_tangent(normal_[slot]);
        if (!has_left) ends_.push_back({slot, -along, false});
        if (!has_right) ends_.push_back({slot, along, false});
      }
      Vec<2> f = ((has_left ? left : 0.0) + (has_right ? right : 0.0)) * t;
      // An end length: the mean traction of this node and its neighbour in the patch (if any).
      if (!has_left && left > 0.0) f += left * (has_right ? 0.5 * (t + node_traction(j + 1)) : t);
      if (!has_right && right > 0.0) f += right * (has_left ? 0.5 * (t + node_traction(j - 1)) : t);
      force += f;
      width += left + right;
      power -= f.dot(Vec<2>(v(i, 0), v(i, 1)));
      // The profile carries the traction the reaction integrates (the end lengths' mean
      // included), so that the sum of its stresses times widths is the body's force.
      const Vec<2>& n = normal_[slot];
      const double a = left + right;
      const Vec<2> te = a > 0.0 ? Vec<2>(f / a) : t;
      profile_.push_back(
          {static_cast<int>(b), i, sj, x[static_cast<std::size_t>(i)], n, a, n.dot(te), body_tangent(n).dot(te)});
    }
    state_[b].force = force;
    state_[b].width = width;
    state_[b].contact_nodes = static_cast<long>(along_.size());
    power_ += power;
  }
}

int RigidContact::faces_body(const Vec<2>& x, const Vec<2>& n_out, double range) const {
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyGap gap = bodies_[b].gap(x, state_[b].offset, depth_);
    // A node on the body's surface (a contact released under tension) is a true free surface.
    if (gap.within && gap.g > keep_ && gap.g <= range && -n_out.dot(gap.normal) > kCos45) return static_cast<int>(b);
  }
  return -1;
}

void RigidContact::reorder_nodes(const std::vector<Index>& order) {
  const auto slots = static_cast<std::size_t>(kMaxContacts);
  permute_rows(body_, order, slots);
  permute_rows(previous_body_, order, slots);
  permute_rows(slip_, order, slots);
  permute_rows(previous_slip_, order, slots);
  permute_rows(normal_, order, slots);
  permute_rows(release_snn_, order, slots);
  permute_rows(in_contact_, order);
  permute_rows(x_begin_, order);
  const std::vector<Index> new_index = inverse_order(order);
  for (ContactPoint& p : profile_) p.node = new_index[static_cast<std::size_t>(p.node)];
}

void RigidContact::save(io::StateArchive& a, const std::string& prefix) const {
  std::vector<double> bodies;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyState& st = state_[b];
    for (const double value :
         {st.offset[0], st.offset[1], st.velocity[0], st.velocity[1], st.force[0], st.force[1], st.width,
          static_cast<double>(st.contact_nodes), static_cast<double>(st.node_projections),
          static_cast<double>(st.stress_point_projections), st.work, st.min_gap, last_power_[b]}) {
      bodies.push_back(value);
    }
  }
  a.put(prefix + "bodies", std::move(bodies));
  a.put(prefix + "slot_body", std::vector<std::int64_t>(body_.begin(), body_.end()));
  a.put(prefix + "slot_slip", std::vector<std::int64_t>(slip_.begin(), slip_.end()));
  a.put_integer(prefix + "selected", selected_ ? 1 : 0);
}

void RigidContact::load(const io::StateArchive& a, const std::string& prefix) {
  const auto& bodies = a.doubles(prefix + "bodies");
  constexpr std::size_t kPerBody = 13;
  for (std::size_t b = 0; b < bodies_.size() && kPerBody * (b + 1) <= bodies.size(); ++b) {
    const double* p = bodies.data() + kPerBody * b;
    BodyState& st = state_[b];
    st.offset = Vec<2>(p[0], p[1]);
    st.velocity = Vec<2>(p[2], p[3]);
    st.force = Vec<2>(p[4], p[5]);
    st.width = p[6];
    st.contact_nodes = static_cast<long>(p[7]);
    st.node_projections = static_cast<long>(p[8]);
    st.stress_point_projections = static_cast<long>(p[9]);
    st.work = p[10];
    st.min_gap = p[11];
    last_power_[b] = p[12];
  }
  const auto& body = a.integers(prefix + "slot_body");
  const auto& slip = a.integers(prefix + "slot_slip");
  for (std::size_t k = 0; k < body_.size() && k < body.size(); ++k) body_[k] = static_cast<int>(body[k]);
  for (std::size_t k = 0; k < slip_.size() && k < slip.size(); ++k) slip_[k] = static_cast<std::int8_t>(slip[k]);
  selected_ = a.integer(prefix + "selected") != 0;
}

bool RigidContact::inside(const Vec<2>& x) const {
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyGap gap = bodies_[b].gap(x, state_[b].offset, depth_);
    if (gap.within && gap.g < 0.0) return true;
  }
  return false;
}

}  // namespace rktsph
