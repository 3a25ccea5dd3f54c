#include "schemes/staggered_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "case/initial_velocity.hpp"
#include "case/size_limits.hpp"
#include "core/error.hpp"
#include "operators/free_surface.hpp"
#include "schemes/registry.hpp"

namespace rktsph {

namespace {

template <int Dim>
SourceRuns make_source_runs(const ParticleSet<Dim>& set, const MaterialTable& materials) {
  SourceRuns runs;
  constexpr Index kChunk = 512;
  Index i = 0;
  while (i < set.size()) {
    const int m = set.material[static_cast<std::size_t>(i)];
    Index j = i;
    while (j < set.size() && set.material[static_cast<std::size_t>(j)] == m && j - i < kChunk) ++j;
    if (materials[m].has_source()) runs.push_back({m, i, j});
    i = j;
  }
  return runs;
}

std::vector<std::string> axis_names(const char* prefix, int dim) {
  std::vector<std::string> out;
  for (int d = 0; d < dim; ++d) out.push_back(fmt::format("{}{}", prefix, kAxisNames[static_cast<std::size_t>(d)]));
  return out;
}

template <int Dim>
std::vector<std::string> stress_names() {
  std::vector<std::string> out(kStressComponents<Dim>);
  for (std::size_t c = 0; c < 6; ++c) {
    const int s = stress_slot<Dim>(static_cast<StressComponent>(c));
    if (s >= 0) out[static_cast<std::size_t>(s)] = fmt::format("s{}", kStressComponentNames[c]);
  }
  return out;
}

}  // namespace

template <int Dim>
StaggeredModel<Dim>::StaggeredModel(CaseSetup<Dim> case_setup, exec::Threads threads)
    : setup(std::move(case_setup)), policy(threads), kernel(setup.smoothing_length()) {
  // Size guards (case/size_limits.hpp) for cases built in code; the case reader has checked a
  // case file already, at the keys' lines. The lattice first, before it is generated.
  auto size_error = [this](const SizeProblem& p) {
    return InputError(fmt::format("{}, key '{}': {}", setup.file, p.full_key(), p.message));
  };
  if (auto p = lattice_size_problem(setup)) throw size_error(*p);
  materials.models = setup.materials;
  for (const auto& m : materials.models) {
    materials.elastic.push_back(m->elastic_rate());
    materials.p_modulus.push_back(m->wave_speed() * m->wave_speed() * m->density());
    materials.density.push_back(m->density());
    materials.any_source = materials.any_source || m->has_source();
  }
  materials.history = HistoryLayout(materials.models);

  LatticeParticles<Dim> lat;
  if (setup.imported) {
    // Particles from files (geometry.particles): without their faces the free surface must be
    // detected (the case reader says so at the key; this is for setups made in code).
    if (!setup.imported->faces_given && !setup.detect_free_surface) {
      throw InputError(
          fmt::format("{}: particles from files without their faces need solver.free_surface = \"detect\" "
                      "(V2 in 2D)",
                      setup.file));
    }
    lat.dx = setup.dx;
    lat.nodes = setup.imported->nodes;
    lat.stress_points = setup.imported->stress_points;
    lat.boundary = setup.imported->boundary;
  } else {
    lat = generate_lattice<Dim>(setup.blocks, setup.dx, setup.origin, materials.density, setup.jitter);
  }
  {
    // The memory estimate with the exact particle counts, before fields and operators.
    const SchemeInfo* scheme = find_scheme<Dim>(setup.version);
    double cells = setup.imported ? 0.0 : 1.0;
    for (const int n : lat.lattice.cells) cells *= static_cast<double>(n);
    if (auto p = memory_problem(setup, scheme != nullptr && scheme->pore_fluid, static_cast<double>(lat.nodes.size()),
                                static_cast<double>(lat.stress_points.size()), cells)) {
      throw size_error(*p);
    }
  }
  lattice = std::move(lat.lattice);
  nodes = std::move(lat.nodes);
  boundary = std::move(lat.boundary);
  if (setup.layout == ParticleLayout::collocated) {
    // Single-set comparison scheme: the half step lives on the nodes themselves.
    stress_points = nodes;
    stress_points.set_name("stress_points");
  } else {
    stress_points = std::move(lat.stress_points);
  }

  // Time step from the wave speed (method-notes §4.3 and §0.3 item 4).
  time_step = time_step_from(setup.dx, max_wave_speed(materials.models), setup.cfl, setup.dt);
  if (time_step.courant > kMaxCourant) {
    throw InputError(fmt::format(
        "{}, key 'time.{}': the Courant number c dt/dx = {:.3f} exceeds {} (c = {:.4g} m/s, "
        "dx = {} m); the scheme is unstable beyond it (method-notes §0.3 item 4)",
        setup.file, setup.dt ? "dt" : "cfl", time_step.courant, kMaxCourant, time_step.wave_speed, setup.dx));
  }

  // Operators, built once from relations that are then dropped: the particles do not move.
  {
    Relation<Dim> relation;
    relation.build(stress_points.position, nodes.position, operator_relation_options(kernel), policy);
    OperatorOptions options;
    options.gradient_floor = setup.gradient_floor;
    to_stress_points = build_corrected_operator<Dim>(relation, stress_points.position, nodes, kernel, options);
    relation.build(nodes.position, stress_points.position, operator_relation_options(kernel), policy);
    to_nodes = build_corrected_operator<Dim>(relation, nodes.position, stress_points, kernel, options);
  }

  // Fields (the order is the order of the output frames).
  const int history = materials.history.stride();
  const unsigned state = kFieldOutput | kFieldEvolving;
  fields.velocity =
      nodes.template add_field<double, Dim>("velocity", axis_names("v", Dim), state, Dim, FieldKind::vector);
  fields.displacement =
      nodes.template add_field<double, Dim>("displacement", axis_names("u", Dim), state, Dim, FieldKind::vector);
  fields.stress = nodes.template add_field<double, NS>("stress", stress_names<Dim>(), state, NS, FieldKind::stress);
  fields.history =
      nodes.template add_field<double, 0>("history", materials.history.names(), state, history, FieldKind::history);
  fields.sp_velocity =
      stress_points.template add_field<double, Dim>("velocity", axis_names("v", Dim), state, Dim, FieldKind::vector);
  fields.sp_stress =
      stress_points.template add_field<double, NS>("stress", stress_names<Dim>(), state, NS, FieldKind::stress);
  fields.sp_history = stress_points.template add_field<double, 0>("history", materials.history.names(), state, history,
                                                                  FieldKind::history);

  node_sources = make_source_runs(nodes, materials);
  stress_point_sources = make_source_runs(stress_points, materials);

  // Rigid bodies in small deformation (method-notes §4.6): the nodes on each body found once,
  // and held by constraints whose value is the body's velocity (smooth: the normal component,
  // rough and bonded: both), appended after the case's entries so that the body wins.
  std::vector<BoundarySpec<Dim>> entries = setup.boundaries;
  if constexpr (Dim == 2) {
    if (!setup.bodies.empty() && setup.version != "v2") {
      const std::vector<std::uint8_t> faces = boundary.dense_faces(nodes.size());
      plates = std::make_shared<RigidPlates>(
          setup.bodies, nodes.position, faces, setup.dx,
          [functions = setup.functions](int f, double t) {
            return f < 0 ? 1.0 : functions[static_cast<std::size_t>(f)](t);
          },
          setup.file);
      for (std::size_t b = 0; b < plates->size(); ++b) {
        const RigidPlates::Plate& p = plates->plates()[b];
        BoundarySpec<Dim> e;
        e.name = p.spec.name;
        e.where = p.spec.where;
        Vec<Dim> lo = nodes.position[static_cast<std::size_t>(p.nodes.front())];
        Vec<Dim> hi = lo;
        for (const Index i : p.nodes) {
          lo = lo.cwiseMin(nodes.position[static_cast<std::size_t>(i)]);
          hi = hi.cwiseMax(nodes.position[static_cast<std::size_t>(i)]);
        }
        e.region = Region<Dim>::box(lo, hi);
        e.velocity.emplace_back(p.normal_axis, 0.0);
        if (p.full) e.velocity.emplace_back(1 - p.normal_axis, 0.0);
        e.body = static_cast<int>(b);
        entries.push_back(std::move(e));
      }
    }
  }
  constraints.resolve(entries, nodes, boundary, setup.dx, !setup.detect_free_surface);
  std::vector<Vec<Dim>> constrained_positions;
  for (const Index i : constraints.constrained())
    constrained_positions.push_back(nodes.position[static_cast<std::size_t>(i)]);
  Relation<Dim> relation;
  relation.build(constrained_positions, stress_points.position, difference_gradient_relation_options(kernel), policy);
  constrained_gradient = build_difference_gradient<Dim>(relation, constrained_positions, stress_points, kernel);

  // Faces of polygons normal to no axis (method-notes §3.9): traction-free by rotation to their
  // geometric normal, which step 2 sees as V2 sees its detected surface (surface rows).
  if (!constraints.rotated().empty()) {
    if (setup.version == "v2") {
      throw InputError(fmt::format(
          "{}: a polygon with edges normal to no axis needs solver.free_surface = \"detect\" in V2 (its "
          "geometric normals hold in the initial configuration only)",
          setup.file));
    }
    const std::vector<Index>& which = constraints.rotated();
    surface.row.assign(static_cast<std::size_t>(nodes.size()), -1);
    for (std::size_t k = 0; k < which.size(); ++k) surface.row[static_cast<std::size_t>(which[k])] = static_cast<Index>(k);
    surface.normal = constraints.rotated_normals();
    surface.corner = constraints.rotated_corners();
    surface.gradient = build_difference_gradient<Dim>(nodes.position, which, stress_points, kernel);
    const auto& tractions = constraints.rotated_tractions();
    if (std::any_of(tractions.begin(), tractions.end(), [](const Vec<Dim>& t) { return t.squaredNorm() > 0.0; })) {
      surface.traction = tractions;
      surface.traction_function = constraints.rotated_functions();
    }
  }
}

template <int Dim>
double StaggeredModel<Dim>::current_wave_speed(double* stretch) const {
  // c_i^2 = M_m / rho_i: the constrained modulus of every material here is constant, so the
  // speed follows the density alone (eq. (4.3.3)).
  const std::vector<double>& modulus = materials.p_modulus;
  double c2 = 0.0, ratio = 0.0;
  for (const ParticleSet<Dim>* set : {&nodes, &stress_points}) {
    for (std::size_t i = 0; i < set->density.size(); ++i) {
      if (set->volume[i] <= 0.0) continue;
      const auto m = static_cast<std::size_t>(set->material[i]);
      c2 = std::max(c2, modulus[m] / set->density[i]);
      ratio = std::max(ratio, materials.density[m] / set->density[i]);
    }
  }
  if (stretch != nullptr) *stretch = ratio;
  return std::sqrt(c2);
}

template <int Dim>
void StaggeredModel<Dim>::stress_points_changed() {
  stress_point_sources = make_source_runs(stress_points, materials);
}

template <int Dim>
void StaggeredModel<Dim>::reorder(const Reordering& r) {
  if (r.empty()) return;
  if (!r.nodes.empty()) {
    if (plates) throw SolverError("the nodes of a case with rigid plates (small deformation) cannot be reordered");
    nodes.permute(r.nodes);
    constraints.remap(r.nodes);
    boundary.remap(r.nodes);
    node_sources = make_source_runs(nodes, materials);
    // Rows by node: the rows themselves stay where they are.
    if (!surface.row.empty()) permute_rows(surface.row, r.nodes);
    if (!contact.row.empty()) permute_rows(contact.row, r.nodes);
  }
  if (!r.stress_points.empty()) {
    stress_points.permute(r.stress_points);
    stress_point_sources = make_source_runs(stress_points, materials);
  }
  ++reorders_;
}

template <int Dim>
void StaggeredModel<Dim>::set_pore_pressure(Field<double, 1> field) {
  fields.pore_pressure = field;
  pore_pressure_ = nodes.view(field).data();
}

template <int Dim>
void StaggeredModel<Dim>::apply_constraints(double t) {
  // Only the few constrained nodes, not the whole set: this runs two or three times a step.
  auto v = nodes.view(fields.velocity);
  auto s = nodes.view(fields.stress);
  for (const Index i : constraints.constrained()) {
    for (Index k = constraints.begin(i); k < constraints.end(i); ++k) {
      const NodalConstraint& c = constraints[k];
      if (released_by_contact(i, c)) continue;
      const double value = constraint_value(i, c, t);  // V3: sigma' = sigma + p_w
      if (c.component < Dim) {
        v(i, c.component) = value;
      } else {
        s(i, c.component - Dim) = value;
      }
    }
  }
  const std::vector<Index>& rotated = constraints.rotated();
  for (std::size_t k = 0; k < rotated.size(); ++k) {
    double* sigma = s[rotated[k]];
    make_surface_traction_free<Dim>(constraints.rotated_normals()[k], constraints.rotated_corners()[k] != 0, sigma);
    if (!surface.traction.empty()) add_surface_traction(k, t, sigma);
  }
}

template <int Dim>
void StaggeredModel<Dim>::add_surface_traction(std::size_t row, double t, double* sigma) const {
  if constexpr (Dim == 2) {
    // method-notes eq. (3.7.2) with sigma_nn = t_n, sigma_nt = t_t and sigma_tt = 0: the part of
    // the stress that the condition prescribes (added to the traction-free part).
    const Vec<Dim>& n = surface.normal[row];
    const double f = function_value(surface.traction_function[row], t);
    const double snn = f * surface.traction[row][0], snt = f * surface.traction[row][1];
    const double c = n[0], sn = n[1];
    sigma[stress_slot<Dim>(0, 0)] += c * c * snn - 2.0 * sn * c * snt;
    sigma[stress_slot<Dim>(1, 1)] += sn * sn * snn + 2.0 * sn * c * snt;
    sigma[stress_slot<Dim>(0, 1)] += sn * c * snn + (c * c - sn * sn) * snt;
  } else {
    (void)row;
    (void)t;
    (void)sigma;
  }
}

template <int Dim>
double StaggeredModel<Dim>::boundary_power() const {
  // Power of the surface tractions: sum over face nodes of A (sigma . n) . v, with the lattice's
  // area and normal. Where the free surface is detected (V2), a face node that no boundary entry
  // selects is traction-free in its current frame and does no work; the lattice normal would
  // count a traction there once the face has turned (a neck).
  const auto v = nodes.view(fields.velocity);
  const auto s = nodes.view(fields.stress);
  double power = 0.0;
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    const Index i = boundary.node[b];
    if (setup.detect_free_surface && constraints.begin(i) == constraints.end(i)) continue;
    const std::uint8_t faces = boundary.faces[b];
    for (int d = 0; d < Dim; ++d) {
      for (int side = 0; side < 2; ++side) {
        if (((faces >> (2 * d + side)) & 1u) == 0) continue;
        const double normal = side == 0 ? -1.0 : 1.0;
        const double area = boundary.area[b][static_cast<std::size_t>(2 * d + side)];
        for (int k = 0; k < Dim; ++k) {
          // V3: the traction is the total stress sigma' - p_w 1.
          const double sk =
              s(i, stress_slot<Dim>(k, d)) - (pore_pressure_ != nullptr && k == d ? pore_pressure_[i] : 0.0);
          power += area * sk * normal * v(i, k);
        }
      }
    }
    if (boundary.has_geometry()) {
      // Faces normal to no axis (polygons): A (sigma . n) . v with the sum of A n over them.
      const Vec<Dim>& a = boundary.inclined[b];
      for (int k = 0; k < Dim; ++k) {
        for (int d = 0; d < Dim; ++d) {
          const double sk =
              s(i, stress_slot<Dim>(k, d)) - (pore_pressure_ != nullptr && k == d ? pore_pressure_[i] : 0.0);
          power += sk * a[d] * v(i, k);
        }
      }
    }
  }
  return power;
}

template <int Dim>
double StaggeredModel<Dim>::imposed_kinetic() const {
  const auto v = nodes.view(fields.velocity);
  double energy = 0.0;
  for (const Index i : constraints.constrained()) {
    for (Index k = constraints.begin(i); k < constraints.end(i); ++k) {
      const int axis = constraints[k].component;
      if (axis < Dim) energy += 0.5 * nodes.mass(i) * v(i, axis) * v(i, axis);
    }
  }
  return energy;
}

template <int Dim>
void StaggeredModel<Dim>::set_initial_state() {
  const auto nn = nodes.size();
  const int vertical = Dim - 1;  // the last axis points up
  const double g = setup.gravity.norm();
  double surface_level = -std::numeric_limits<double>::infinity();
  for (const auto& x : nodes.position) surface_level = std::max(surface_level, x[vertical]);
  if (setup.surface_level) surface_level = *setup.surface_level;
  auto v = nodes.view(fields.velocity);
  auto s = nodes.view(fields.stress);
  auto k = nodes.view(fields.history);
  const InitialVelocityField<Dim> initial_velocity(setup.initial_velocities);
  for (Index i = 0; i < nn; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const int m = nodes.material[iu];
    const Vec<Dim> v0 = initial_velocity.at(nodes.position[iu], m);
    for (int d = 0; d < Dim; ++d) v(i, d) = v0[d];
    if (setup.initial_stress == InitialStressKind::geostatic) {
      // method-notes §4.2 option A: sigma_v = -rho g (H - z), lateral = K0 sigma_v.
      const double nu = materials[m].elastic().nu;
      const double k0 = setup.k0.value_or(nu / (1.0 - nu));
      const double sv = -nodes.density[iu] * g * (surface_level - nodes.position[iu][vertical]);
      for (int n = 0; n < 3; ++n) s(i, n) = (n == vertical ? 1.0 : k0) * sv;
    } else if (setup.initial_stress == InitialStressKind::uniform) {
      from_sym6<Dim>(setup.uniform_stress, s[i]);
    }
    if (k.components() > 0) materials[m].initial_state(to_sym6<Dim>(s[i]), k[i]);
  }
  apply_constraints(0.0);
  if constexpr (Dim == 2) {
    if (plates) {
      const auto st = nodes.view(fields.stress);
      plates->measure({st.data(), st.size(), RigidPlates::NS}, pore_pressure_);
    }
  }

  // The stress points' state at t = 0: the nodal state interpolated to them, as step 1 starts
  // from it (method-notes §3.3: nodes are primary). Only the t = 0 output reads it: step 1
  // overwrites every stress point's velocity, stress and history before anything uses them.
  const auto node_v = std::as_const(nodes).view(fields.velocity);
  const auto node_s = std::as_const(nodes).view(fields.stress);
  const auto node_k = std::as_const(nodes).view(fields.history);
  auto sp_v = stress_points.view(fields.sp_velocity);
  auto sp_s = stress_points.view(fields.sp_stress);
  auto sp_k = stress_points.view(fields.sp_history);
  const int stride = sp_k.components();
  exec::particle_for(policy, stress_points.size(), [&](Index e) {
    for (int d = 0; d < Dim; ++d) sp_v(e, d) = 0.0;
    for (int c = 0; c < NS; ++c) sp_s(e, c) = 0.0;
    for (int j = 0; j < stride; ++j) sp_k(e, j) = 0.0;
    const auto row = to_stress_points.row(e);
    for (Index q = row.begin; q < row.end; ++q) {
      const Index i = to_stress_points.source(row, q);
      const double w = to_stress_points.interp[static_cast<std::size_t>(q)];
      for (int d = 0; d < Dim; ++d) sp_v(e, d) += w * node_v(i, d);
      for (int c = 0; c < NS; ++c) sp_s(e, c) += w * node_s(i, c);
      for (int j = 0; j < stride; ++j) sp_k(e, j) += w * node_k(i, j);
    }
  });
}

template <int Dim>
std::size_t StaggeredModel<Dim>::operator_bytes() const {
  return to_stress_points.bytes() + to_nodes.bytes() +
         constrained_gradient.source.size() * (sizeof(Index) + sizeof(Vec<Dim>)) + constraints.bytes();
}

template class StaggeredModel<1>;
template class StaggeredModel<2>;
template class StaggeredModel<3>;

}  // namespace rktsph
