// The limit-equilibrium problem of a case file: bodies, soil strength and weight, rigid regions.
#include "lem/lem_case.hpp"

#include <cmath>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "case/material_reader.hpp"
#include "core/error.hpp"
#include "io/section.hpp"

namespace rktsph::lem {

namespace {

std::string line_of(const toml::node& n) {
  const auto line = n.source().begin.line;
  return line > 0 ? fmt::format(" (line {})", line) : std::string();
}

// A ring [[x, y], ...] from the node `n` of key `key` of `s`; `what` names it in messages
// ("vertices", "hole 2").
std::vector<Point> read_ring(const io::Section& s, std::string_view key, const toml::node& n, const std::string& what) {
  const toml::array* arr = n.as_array();
  if (arr == nullptr) s.fail(key, fmt::format("{}: must be an array of [x, y] points in m", what));
  std::vector<Point> ring;
  std::size_t k = 0;
  for (const toml::node& item : *arr) {
    const toml::array* xy = item.as_array();
    std::optional<double> x, y;
    if (xy != nullptr && xy->size() == 2) {
      x = (*xy)[0].value<double>();
      y = (*xy)[1].value<double>();
    }
    if (!x || !y || !std::isfinite(*x) || !std::isfinite(*y) || std::abs(*x) > io::Section::kMaxMagnitude ||
        std::abs(*y) > io::Section::kMaxMagnitude) {
      s.fail(key, fmt::format("{}: point {}{} must be [x, y], two finite numbers in m", what, k, line_of(item)));
    }
    ring.push_back({*x, *y});
    ++k;
  }
  // Closed or not: a last point equal to the first closes the ring.
  if (ring.size() >= 2 && ring.front().x == ring.back().x && ring.front().y == ring.back().y) ring.pop_back();
  if (ring.size() < 3) s.fail(key, fmt::format("{}: needs at least 3 distinct points, got {}", what, ring.size()));
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Point a = ring[i], b = ring[(i + 1) % ring.size()];
    if (a.x == b.x && a.y == b.y) s.fail(key, fmt::format("{}: points {} and {} coincide", what, i, (i + 1) % ring.size()));
  }
  std::size_t e1 = 0, e2 = 0;
  if (self_intersects(ring, &e1, &e2)) {
    s.fail(key, fmt::format("{}: the polygon intersects itself (edge {} meets edge {}; edge i runs from point i to i+1)",
                            what, e1, e2));
  }
  return ring;
}

struct MaterialStrength {
  std::string name;
  std::string model;
  double cohesion = 0.0;
  double friction_angle = 0.0;  // rad
  double density = 0.0;
};

// c and phi of a material table, checked: a model with no c-phi strength is an error here.
MaterialStrength read_strength(const io::Section& m, const std::string& name) {
  MaterialStrength out;
  out.name = name;
  out.model = m.string("model");
  const std::string supported = "perzyna_von_mises (c, phi = 0), perzyna_drucker_prager, perzyna_mohr_coulomb";
  if (out.model == "elastic") {
    m.fail("model", fmt::format("an elastic material has no strength; the limit-equilibrium analysis needs {}", supported));
  }
  if (out.model == "perzyna_cam_clay") {
    m.fail("model", fmt::format("Cam-Clay has no cohesion and friction angle (its strength depends on p_c and the "
                                "stress path); the limit-equilibrium analysis needs {}",
                                supported));
  }
  if (out.model == "perzyna_von_mises") {
    if (m.has("cohesion")) {
      out.cohesion = m.number("cohesion");
    } else if (m.has("yield_stress")) {
      out.cohesion = m.number("yield_stress") / std::sqrt(3.0);  // c = sigma_Y / sqrt(3), materials.md
    }
    out.friction_angle = 0.0;
    if (!(out.cohesion > 0.0)) {
      m.fail(m.has("yield_stress") ? "yield_stress" : "cohesion",
             fmt::format("no strength: cohesion {} Pa and friction angle 0; the limit-equilibrium analysis needs "
                         "c > 0 or phi > 0",
                         out.cohesion));
    }
  } else if (out.model == "perzyna_drucker_prager" || out.model == "perzyna_mohr_coulomb") {
    out.cohesion = m.number("cohesion");
    const double phi_deg = m.number("friction_angle");
    out.friction_angle = phi_deg * std::numbers::pi / 180.0;
    if (!(out.cohesion > 0.0) && !(phi_deg > 0.0)) {
      m.fail("cohesion", fmt::format("no strength: cohesion {} Pa and friction angle {} degrees; the "
                                     "limit-equilibrium analysis needs c > 0 or phi > 0",
                                     out.cohesion, phi_deg));
    }
  }
  // Every key checked as the particle solver checks it (an unknown model is reported here).
  const auto material = read_material(m);
  m.finish();
  out.density = material->density();
  return out;
}

}  // namespace

LemProblem read_lem_problem(const CaseDocument& doc) {
  io::Section root(doc.table, "", doc.file_label);
  const io::Section g = root.table("geometry");
  const auto dim = g.integer("dimension");
  if (dim != 2) g.fail("dimension", fmt::format("the limit-equilibrium analysis is two-dimensional, got {}", dim));
  if (g.has("particles")) {
    g.fail("particles", "the limit-equilibrium analysis needs the bodies' outlines: give [[geometry.polygon]] or "
                        "[[geometry.block]] entries, not particles from files");
  }

  // ---- materials
  std::vector<std::string> names;
  std::vector<io::Section> tables;
  const bool single = root.has("material");
  if (single && root.has("materials")) root.fail("materials", "give either [material] or [materials.NAME], not both");
  if (single) {
    names.emplace_back("material");
    tables.push_back(root.table("material"));
  } else if (root.has("materials")) {
    const io::Section ms = root.table("materials");
    for (const std::string& name : ms.keys()) {
      names.push_back(name);
      tables.push_back(ms.table(name));
    }
  } else {
    root.fail("material", "missing: the case needs a [material] table");
  }
  std::vector<std::optional<MaterialStrength>> strengths(names.size());
  auto material_of = [&](const io::Section& body) -> const MaterialStrength& {
    std::size_t index = 0;
    if (body.has("material")) {
      const std::string name = body.string("material");
      index = names.size();
      for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == name) index = i;
      }
      if (index == names.size()) {
        body.fail("material", fmt::format("unknown material '{}' (the case has: {})", name, fmt::join(names, ", ")));
      }
    } else if (names.size() != 1) {
      body.fail("material", fmt::format("missing: the case has several materials ({}); name one", fmt::join(names, ", ")));
    }
    if (!strengths[index]) strengths[index] = read_strength(tables[index], names[index]);
    return *strengths[index];
  };

  // ---- bodies: polygons and blocks, each with its material's soil
  std::vector<Body> bodies;
  std::vector<const MaterialStrength*> body_material;
  auto add_body = [&](const io::Section& s, Body body) {
    body_material.push_back(&material_of(s));
    body.name = s.path();
    bodies.push_back(std::move(body));
  };
  for (const io::Section& p : g.tables("polygon")) {
    Body body;
    const toml::node* vertices = p.raw().get("vertices");
    if (vertices == nullptr) p.fail("vertices", "missing: the polygon's points [[x, y], ...] in m, counter-clockwise");
    body.outer = read_ring(p, "vertices", *vertices, "vertices");
    if (signed_area(body.outer) <= 0.0) {
      p.fail("vertices", "the vertices run clockwise; give them counter-clockwise (the soil on the left of each edge)");
    }
    if (p.has("holes")) {
      const toml::array* holes = p.raw().get("holes")->as_array();
      if (holes == nullptr) p.fail("holes", "must be an array of rings, each an array of [x, y] points");
      for (std::size_t h = 0; h < holes->size(); ++h) {
        std::vector<Point> ring = read_ring(p, "holes", *holes->get(h), fmt::format("hole {}", h));
        Body outer_only;
        outer_only.outer = body.outer;
        for (const Point& q : ring) {
          if (!SoilGeometry({outer_only}, {}).contains(q)) {
            p.fail("holes", fmt::format("hole {}: a point ({}, {}) lies outside the polygon's vertices", h, q.x, q.y));
          }
        }
        body.holes.push_back(std::move(ring));
      }
    }
    add_body(p, std::move(body));
  }
  for (const io::Section& b : g.tables("block")) {
    const auto lo = b.numbers("min"), hi = b.numbers("max");
    if (lo.size() != 2) b.fail("min", "must have 2 coordinates for a 2D case");
    if (hi.size() != 2) b.fail("max", "must have 2 coordinates for a 2D case");
    if (!(hi[0] > lo[0] && hi[1] > lo[1])) b.fail("max", "must exceed 'min' in every coordinate");
    Body body;
    body.outer = {{lo[0], lo[1]}, {hi[0], lo[1]}, {hi[0], hi[1]}, {lo[0], hi[1]}};
    add_body(b, std::move(body));
  }
  if (bodies.empty()) {
    g.fail("", "no bodies: the limit-equilibrium analysis needs [[geometry.polygon]] or [[geometry.block]] entries");
  }

  // ---- gravity
  const auto bf = root.optional_table("body_force");
  if (!bf || !bf->has("gravity")) {
    root.fail("body_force", "missing gravity: the limit-equilibrium analysis needs body_force.gravity = [0, -g]");
  }
  const auto gravity = bf->numbers("gravity");
  if (gravity.size() != 2 || gravity[0] != 0.0 || !(gravity[1] < 0.0)) {
    bf->fail("gravity", "the limit-equilibrium analysis needs a vertical gravity [0, -g] with g > 0 m/s^2");
  }

  LemProblem out{SoilGeometry({}, {}), {}, {}, {}, {}, {}, {}, {}};
  out.title = root.string("title", "");
  const MaterialStrength* soil = body_material.front();  // the first body's, for the summary
  out.material_name = soil->name;
  out.model = soil->model;
  out.density = soil->density;
  out.gravity = -gravity[1];
  out.soil = {soil->cohesion, soil->friction_angle, soil->density * out.gravity};
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const MaterialStrength& m = *body_material[i];
    bodies[i].soil = Soil{m.cohesion, m.friction_angle, m.density * out.gravity};
    bodies[i].material = m.name;
  }
  if (bf->has("function")) {
    out.notes.push_back("body_force.function is not applied: the analysis takes the full gravity");
  }

  // ---- rigid regions: the [[boundary]] entries that prescribe a velocity
  std::vector<RigidRegion> rigid;
  for (const io::Section& b : root.tables("boundary")) {
    if (!b.has("velocity")) {
      if (b.has("stress")) out.notes.push_back(fmt::format("{}: boundary stresses are not included", b.where()));
      continue;
    }
    if (!b.has("x") && !b.has("y")) {
      // A selection the analysis cannot see as a box (e.g. by an edge of a polygon) must not
      // silently make the whole plane rigid.
      b.fail("", "prescribes a velocity but selects no x/y box; the limit-equilibrium analysis takes the rigid "
                 "regions from x = [min, max] and y = [min, max] ranges only");
    }
    RigidRegion r;
    r.name = b.string("name", b.path());
    for (int d = 0; d < 2; ++d) {
      const std::string_view axis = d == 0 ? "x" : "y";
      if (!b.has(axis)) continue;
      const auto range = b.numbers(axis);
      if (range.size() != 2 || range[1] < range[0]) b.fail(axis, "must be a range [min, max] in m with min <= max");
      r.lo[static_cast<std::size_t>(d)] = range[0];
      r.hi[static_cast<std::size_t>(d)] = range[1];
    }
    rigid.push_back(r);
  }
  out.geometry = SoilGeometry(std::move(bodies), {});
  if (rigid.empty()) {
    RigidRegion base;
    base.lo[1] = base.hi[1] = out.geometry.y_min();
    base.name = "lowest level of the soil";
    rigid.push_back(base);
    out.notes.push_back(fmt::format("no [[boundary]] entry prescribes a velocity: the soil's lowest level y = {} m "
                                    "is taken as a rigid base",
                                    out.geometry.y_min()));
  }
  out.geometry = SoilGeometry(out.geometry.bodies(), std::move(rigid));
  out.notes.push_back("tension cracks, pore pressures and external loads are not modelled");
  return out;
}

}  // namespace rktsph::lem
