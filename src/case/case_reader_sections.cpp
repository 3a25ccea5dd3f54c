// The readers of one boundary entry, one probe and the particle files
// (case/case_reader_sections.hpp); every error names the file, the line and the key.
#include "case/case_reader_sections.hpp"

#include <filesystem>
#include <limits>

#include "case/initial_velocity.hpp"
#include "case/particle_file_reader.hpp"
#include "case/polygon_reader.hpp"
#include "core/error.hpp"

namespace rktsph::case_reading {

namespace {

/// The axes of a Dim-D case, for messages: "x", "x, y" or "x, y, z".
constexpr std::string_view axis_list(int dim) { return dim == 1 ? "x" : dim == 2 ? "x, y" : "x, y, z"; }

/// The stress components that act on a face of the body, which a boundary entry can prescribe:
/// in 2D (plane strain) not zz, which acts on no face.
constexpr std::string_view face_stress_components(int dim) {
  return dim == 1 ? "xx" : dim == 2 ? "xx, yy, xy" : "xx, yy, zz, xy, yz, xz";
}

/// The keys x, y, z (each [min, max], m) of a node selector into `region`; false when none is given.
template <int Dim>
bool read_axis_ranges(const io::Section& s, Region<Dim>& region) {
  bool any_axis = false;
  for (int d = 0; d < Dim; ++d) {
    const std::string axis(kAxisNames[static_cast<std::size_t>(d)]);
    if (!s.has(axis)) {
      s.number(axis, 0.0);
      continue;
    }
    const auto range = s.numbers(axis);
    if (range.size() != 2 || range[1] < range[0]) {
      s.fail(axis, "must be a range [min, max] in m with min <= max (use [a, a] for a plane)");
    }
    region.lo[static_cast<std::size_t>(d)] = range[0];
    region.hi[static_cast<std::size_t>(d)] = range[1];
    region.bounded[static_cast<std::size_t>(d)] = true;
    any_axis = true;
  }
  return any_axis;
}

}  // namespace

template <int Dim>
BoundarySpec<Dim> read_boundary(const io::Section& b, const CaseSetup<Dim>& c) {
  BoundarySpec<Dim> spec;
  spec.name = b.string("name", b.path());
  spec.where = b.where();
  // A polygon's edge (case/polygon_reader.hpp), or a region.
  const bool by_edge = read_boundary_edge<Dim>(b, c, spec);
  if (!by_edge && !read_axis_ranges(b, spec.region)) {
    b.fail("", fmt::format("selects no region: give at least one of {} as [min, max]{}", axis_list(Dim),
                           Dim == 2 ? ", or a polygon's edge (polygon, edge)" : ""));
  }
  if (auto v = b.optional_table("velocity")) {
    for (const std::string& axis : v->keys()) {
      const int a = axis_of(axis);
      if (a < 0 || a >= Dim) {
        v->fail(axis, fmt::format("unknown velocity component (a {}D case has: {})", Dim, axis_list(Dim)));
      }
      spec.velocity.emplace_back(a, v->number(axis));
    }
    v->finish();
  }
  if (auto st = b.optional_table("stress")) {
    for (const std::string& comp : st->keys()) {
      // Only the components that act on a face of the body can be prescribed.
      const bool allowed = comp == "xx" || (Dim >= 2 && (comp == "yy" || comp == "xy")) ||
                           (Dim == 3 && (comp == "zz" || comp == "yz" || comp == "xz"));
      if (!allowed) {
        st->fail(comp, fmt::format("not a stress component that can be prescribed in {}D "
                                   "(use {})",
                                   Dim, face_stress_components(Dim)));
      }
      int slot = -1;
      for (std::size_t i = 0; i < 6; ++i) {
        if (kStressComponentNames[i] == comp) slot = stress_slot<Dim>(static_cast<StressComponent>(i));
      }
      spec.stress.emplace_back(slot, st->number(comp));
    }
    st->finish();
  }
  if (auto tr = b.optional_table("traction")) {
    // A traction on an inclined polygon edge (method-notes §3.9), about the edge's normal.
    if (!spec.edge) tr->fail("", "acts on a polygon edge normal to no axis: select it with polygon and edge");
    const Ring& ring = c.polygons[static_cast<std::size_t>(spec.edge->body)].ring(spec.edge->ring);
    const Vec<2> d = ring[(static_cast<std::size_t>(spec.edge->edge) + 1) % ring.size()] -
                     ring[static_cast<std::size_t>(spec.edge->edge)];
    if (d[0] == 0.0 || d[1] == 0.0) {
      tr->fail("", "acts on edges normal to no axis; on this edge give the stress components (stress = {...})");
    }
    if (!spec.velocity.empty() || !spec.stress.empty()) {
      tr->fail("", "give either a traction or velocity / stress components on an edge, not both");
    }
    spec.traction = std::array<double, 2>{tr->number("n", 0.0), tr->number("t", 0.0)};
    tr->finish();
  }
  // V3 pore-pressure conditions (checked against solver.version below).
  if (b.has("pore_pressure"))
    spec.pore_pressure = b.number("pore_pressure");
  else
    b.number("pore_pressure", 0.0);
  spec.impermeable = b.boolean("impermeable", false);
  if (spec.pore_pressure && spec.impermeable) {
    b.fail("impermeable", "a face is either drained (pore_pressure) or impermeable, not both");
  }
  if (spec.velocity.empty() && spec.stress.empty() && !spec.traction && !spec.pore_pressure && !spec.impermeable) {
    b.fail("",
           "prescribes nothing: give a velocity = {...} or stress = {...} table (or, with "
           "solver.version = \"v3\", pore_pressure or impermeable)");
  }
  spec.function = function_index(c, b, "function");
  b.finish();
  return spec;
}

template <int Dim>
InitialVelocitySpec<Dim> read_initial_velocity(const io::Section& s, const CaseSetup<Dim>& c) {
  InitialVelocitySpec<Dim> spec;
  spec.where = s.where();
  read_axis_ranges(s, spec.region);  // none: every node
  if (s.has("material")) {
    spec.material = material_index(c.material_names, s, "material");
  } else {
    s.string("material", "");
  }
  if (s.has("velocity"))
    spec.velocity = read_vector<Dim>(s, "velocity");
  else
    s.number("velocity", 0.0);
  if (s.has("angular_velocity")) {
    // 2D: a number (about e_z); 3D: the vector [wx, wy, wz]; 1D has no rotation.
    if constexpr (Dim == 1) {
      s.fail("angular_velocity", "a rigid rotation needs a 2D or 3D case");
    } else if constexpr (Dim == 2) {
      spec.angular_velocity = s.number("angular_velocity");
    } else {
      spec.angular_velocity_vector = read_vector<3>(s, "angular_velocity");
    }
    if (s.has("centre"))
      spec.centre = read_vector<Dim>(s, "centre");
    else
      s.number("centre", 0.0);
  } else {
    s.number("angular_velocity", 0.0);
    s.number("centre", 0.0);
  }
  if (auto f = s.optional_table("function")) {
    for (const std::string& axis : f->keys()) {
      const int a = axis_of(axis);
      if (a < 0 || a >= Dim) {
        f->fail(axis, fmt::format("unknown velocity component (a {}D case has: {})", Dim, axis_list(Dim)));
      }
      const std::string expression = f->string(axis);
      check_position_expression(expression, Dim, f->where(axis));
      spec.expression[static_cast<std::size_t>(a)] = expression;
    }
    f->finish();
  }
  s.finish();
  return spec;
}

template <int Dim>
ProbeSpec read_probe(const io::Section& p, const CaseSetup<Dim>& c) {
  ProbeSpec spec;
  spec.name = p.string("name");
  // The name heads columns of probes.csv ("name.field"): nothing that breaks a CSV header.
  p.require(!spec.name.empty(), "name", "must not be empty (it heads the probe's columns in probes.csv)");
  for (const char ch : spec.name) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == ',' || ch == '"' || u < 0x20 || u == 0x7f) {
      p.fail("name", fmt::format("must not contain {} (the name heads the probe's columns in probes.csv)",
                                 ch == ','   ? std::string("a comma")
                                 : ch == '"' ? std::string("a double quote")
                                             : fmt::format("a control character (code {})", static_cast<int>(u))));
    }
  }
  spec.where = p.where("position");
  spec.position = p.numbers("position");
  if (static_cast<int>(spec.position.size()) != Dim) {
    p.fail("position", fmt::format("must have {} coordinate{} for a {}D case", Dim, Dim > 1 ? "s" : "", Dim));
  }
  spec.fields_where = p.where("fields");
  spec.fields = p.strings("fields");
  p.require(!spec.fields.empty(), "fields", "must name at least one field");
  for (const auto& other : c.probes) {
    if (other.name == spec.name) p.fail("name", fmt::format("probe name '{}' is used twice", spec.name));
  }
  p.finish();
  return spec;
}

template <int Dim>
typename CaseSetup<Dim>::ImportedParticles read_imported_particles(const CaseDocument& doc,
                                                                   const std::vector<io::Section>& entries,
                                                                   const CaseSetup<Dim>& c) {
  ParticleFileMaterials materials;
  materials.names = c.material_names;
  for (const auto& m : c.materials) materials.densities.push_back(m->density());
  typename CaseSetup<Dim>::ImportedParticles out;
  struct Origin {
    std::size_t entry;
    long line;
  };
  std::vector<Origin> node_origin, stress_point_origin;
  std::vector<std::string> node_file, stress_point_file;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const io::Section& e = entries[k];
    for (const char* key : {"nodes", "stress_points"}) {
      const std::string name = e.string(key);
      e.require(!name.empty(), key, "must name a CSV file");
      std::filesystem::path path(name);
      if (path.is_relative() && !doc.directory.empty()) path = std::filesystem::path(doc.directory) / path;
      const bool nodes = std::string_view(key) == "nodes";
      auto& set = nodes ? out.nodes : out.stress_points;
      bool faces_given = false;
      const auto lines = read_particle_file<Dim>(path.string(), name, e.where(key), materials, set,
                                                 nodes ? &out.boundary : nullptr, &faces_given);
      if (nodes && k > 0 && faces_given != out.faces_given) {
        e.fail(key, fmt::format("{} {} the face columns and geometry.particles[0].nodes {}: give them in every "
                                "node file or in none",
                                name, faces_given ? "has" : "lacks", out.faces_given ? "has" : "does not"));
      }
      if (nodes) out.faces_given = faces_given;
      for (const long line : lines) (nodes ? node_origin : stress_point_origin).push_back({k, line});
      (nodes ? node_file : stress_point_file).push_back(name);
    }
    e.finish();
  }
  const double tolerance = 1e-6 * c.dx;
  for (const char* key : {"nodes", "stress_points"}) {
    const bool nodes = std::string_view(key) == "nodes";
    const auto& set = nodes ? out.nodes : out.stress_points;
    const auto& origin = nodes ? node_origin : stress_point_origin;
    const auto& file = nodes ? node_file : stress_point_file;
    const auto [a, b] = coincident_particles<Dim>(set, tolerance);
    if (a < 0) continue;
    const Origin& first = origin[static_cast<std::size_t>(a)];
    const Origin& second = origin[static_cast<std::size_t>(b)];
    std::vector<double> x(set.position[static_cast<std::size_t>(b)].data(),
                          set.position[static_cast<std::size_t>(b)].data() + Dim);
    entries[second.entry].fail(key, fmt::format("{}, line {}: the particle at ({}) coincides with the one of {}, line "
                                                "{} (closer than 1e-6 spacings, {:.3g} m)",
                                                file[second.entry], second.line, fmt::join(x, ", "), file[first.entry],
                                                first.line, tolerance));
  }
  return out;
}

template BoundarySpec<1> read_boundary<1>(const io::Section&, const CaseSetup<1>&);
template BoundarySpec<2> read_boundary<2>(const io::Section&, const CaseSetup<2>&);
template BoundarySpec<3> read_boundary<3>(const io::Section&, const CaseSetup<3>&);
template InitialVelocitySpec<1> read_initial_velocity<1>(const io::Section&, const CaseSetup<1>&);
template InitialVelocitySpec<2> read_initial_velocity<2>(const io::Section&, const CaseSetup<2>&);
template InitialVelocitySpec<3> read_initial_velocity<3>(const io::Section&, const CaseSetup<3>&);
template ProbeSpec read_probe<1>(const io::Section&, const CaseSetup<1>&);
template ProbeSpec read_probe<2>(const io::Section&, const CaseSetup<2>&);
template ProbeSpec read_probe<3>(const io::Section&, const CaseSetup<3>&);
template CaseSetup<1>::ImportedParticles read_imported_particles<1>(const CaseDocument&,
                                                                    const std::vector<io::Section>&,
                                                                    const CaseSetup<1>&);
template CaseSetup<2>::ImportedParticles read_imported_particles<2>(const CaseDocument&,
                                                                    const std::vector<io::Section>&,
                                                                    const CaseSetup<2>&);
template CaseSetup<3>::ImportedParticles read_imported_particles<3>(const CaseDocument&,
                                                                    const std::vector<io::Section>&,
                                                                    const CaseSetup<3>&);

}  // namespace rktsph::case_reading
