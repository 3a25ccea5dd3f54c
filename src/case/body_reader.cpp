#include "case/body_reader.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "case/case_reader_sections.hpp"
#include "core/error.hpp"

namespace rktsph::case_reading {

namespace {

// velocity = {x = ..., y = ...} or force = {...}: per axis a number, or the name of a time
// function whose value is the component.
void read_components(const io::Section& t, const CaseSetup<2>& c, std::array<double, 2>& value,
                     std::array<int, 2>& function, std::array<bool, 2>& given) {
  for (const std::string& axis : t.keys()) {
    const int a = axis_of(axis);
    if (a < 0 || a >= 2) t.fail(axis, "unknown component (a 2D case has: x, y)");
    const auto au = static_cast<std::size_t>(a);
    given[au] = true;
    if (t.raw()[axis].is_string()) {
      value[au] = 1.0;
      function[au] = function_index(c, t, axis);
    } else {
      value[au] = t.number(axis);
      function[au] = -1;
    }
  }
  t.finish();
}

}  // namespace

BodySpec read_body(const io::Section& b, const CaseSetup<2>& c, std::size_t index) {
  BodySpec spec;
  spec.name = b.string("name", fmt::format("body{}", index + 1));
  spec.where = b.where();
  const int shapes = (b.has("plane") ? 1 : 0) + (b.has("segment") ? 1 : 0) + (b.has("polyline") ? 1 : 0);
  if (shapes != 1) {
    b.fail("", shapes == 0 ? "has no geometry: give one of plane = {point, normal}, segment = {a, b} or "
                             "polyline = [[x, y], ...]"
                           : "has more than one geometry: give only one of plane, segment and polyline");
  }
  if (auto p = b.optional_table("plane")) {
    spec.shape = BodyShape::plane;
    spec.points = {read_vector<2>(*p, "point")};
    spec.normal = read_vector<2>(*p, "normal");
    const double len = spec.normal.norm();
    if (!(len > 0.0)) p->fail("normal", "must be a non-zero vector (it points into the soil)");
    spec.normal /= len;
    p->finish();
  } else if (auto s = b.optional_table("segment")) {
    spec.shape = BodyShape::segment;
    spec.points = {read_vector<2>(*s, "a"), read_vector<2>(*s, "b")};
    if ((spec.points[1] - spec.points[0]).norm() <= 0.0) {
      s->fail("b", "coincides with a: the body has no segment");
    }
    s->finish();
  } else {
    spec.shape = BodyShape::polyline;
    for (const auto& row : b.number_rows("polyline", 2)) spec.points.emplace_back(row[0], row[1]);
    if (spec.points.size() < 2) b.fail("polyline", "has no segment: give at least two points [[x, y], ...]");
    for (std::size_t k = 0; k + 1 < spec.points.size(); ++k) {
      if ((spec.points[k + 1] - spec.points[k]).norm() <= 0.0) {
        b.fail("polyline", fmt::format("points {} and {} coincide: a segment of no length", k + 1, k + 2));
      }
    }
  }

  const std::string law = b.string("contact", "rough");
  if (law == "rough")
    spec.law = ContactLaw::rough;
  else if (law == "smooth")
    spec.law = ContactLaw::smooth;
  else if (law == "coulomb")
    spec.law = ContactLaw::coulomb;
  else if (law == "bonded")
    spec.law = ContactLaw::bonded;
  else
    b.fail("contact", fmt::format("unknown contact law '{}' (known: rough, smooth, coulomb, bonded)", law));
  spec.friction = b.number("friction", 0.0);
  if (!(spec.friction >= 0.0)) b.fail("friction", fmt::format("must be >= 0, got {}", spec.friction));
  if (b.has("friction") && spec.law != ContactLaw::coulomb) {
    b.fail("friction", "a friction coefficient needs contact = \"coulomb\"");
  }
  spec.adhesion = b.number("adhesion", 0.0);
  if (!(spec.adhesion >= 0.0)) b.fail("adhesion", fmt::format("must be >= 0 Pa, got {}", spec.adhesion));
  const std::string release = b.string("release", "node");
  if (release == "patch")
    spec.release_on_patch_mean = true;
  else if (release != "node")
    b.fail("release", fmt::format("unknown release rule '{}' (known: node, patch)", release));

  std::array<bool, 2> prescribed{false, false};
  if (auto v = b.optional_table("velocity")) {
    read_components(*v, c, spec.velocity, spec.velocity_function, prescribed);
  }
  if (auto f = b.optional_table("force")) {
    read_components(*f, c, spec.force, spec.force_function, spec.force_driven);
    for (std::size_t d = 0; d < 2; ++d) {
      if (spec.force_driven[d] && prescribed[d]) {
        f->fail(std::string(kAxisNames[d]), "the component is given both a velocity and a force: give one");
      }
    }
  }
  if (spec.any_force()) {
    spec.mass = b.positive("mass");
  } else if (b.has("mass")) {
    b.fail("mass", "a mass is only used by a force-driven body (force = {...})");
  } else {
    b.number("mass", 0.0);
  }
  b.finish();
  return spec;
}

}  // namespace rktsph::case_reading
