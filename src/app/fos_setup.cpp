#include "app/fos_setup.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"
#include "io/section.hpp"
#include "schemes/simulation.hpp"

namespace rktsph::fos {

double reduced_friction_angle(double phi_degrees, double factor) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  return std::atan(std::tan(phi_degrees * kDeg) / factor) / kDeg;
}

std::vector<std::pair<std::string, double>> StrengthReduction::values(double factor) const {
  std::vector<std::pair<std::string, double>> out;
  for (const MaterialStrength& m : materials) {
    // method-notes eq. (10.1): every strength in stress units over F, tan(phi) over F, and the
    // dilatancy kept unless it would exceed the reduced friction angle.
    for (const auto& [key, value] : m.divided) out.emplace_back(m.table + "." + key, value / factor);
    if (m.friction_angle) {
      const double phi = reduced_friction_angle(*m.friction_angle, factor);
      out.emplace_back(m.table + ".friction_angle", phi);
      if (m.dilatancy) out.emplace_back(m.table + ".dilatancy", std::min(*m.dilatancy, phi));
    }
  }
  return out;
}

namespace {

/// The table `path` of a case's document, which the reader has already checked to be there:
/// "material", or "materials.NAME" / "functions.NAME" (NAME may hold dots).
toml::table& table_at(toml::table& root, const std::string& path) {
  const std::size_t dot = path.find('.');
  toml::table* t = root[path.substr(0, dot)].as_table();
  if (t != nullptr && dot != std::string::npos) t = (*t)[path.substr(dot + 1)].as_table();
  if (t == nullptr) throw std::logic_error("fos: no table " + path + " in the case");
  return *t;
}

// "table.key" -> (table, key): the key is the part after the last dot.
void set_value(toml::table& root, const std::string& dotted, double value) {
  const std::size_t dot = dotted.rfind('.');
  table_at(root, dotted.substr(0, dot)).insert_or_assign(dotted.substr(dot + 1), value);
}

}  // namespace

void StrengthReduction::apply(toml::table& root, double factor) const {
  for (const auto& [key, value] : values(factor)) set_value(root, key, value);
  if (!rate_independent) return;
  // The rate-independent limit of each reduced Perzyna model (method-notes §2.5): the return
  // mapping of the same surface and flow rule.
  for (const MaterialStrength& m : materials) {
    table_at(root, m.table).insert_or_assign("fluidity", std::numeric_limits<double>::infinity());
  }
}

std::vector<std::pair<std::string, double>> LoadScaling::values(double factor) const {
  // method-notes eq. (10.4): every load a named function scales, times F.
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [table, scale] : functions) out.emplace_back(table + ".scale", scale * factor);
  return out;
}

void LoadScaling::apply(toml::table& root, double factor) const {
  for (const auto& [key, value] : values(factor)) set_value(root, key, value);
}

namespace {

std::optional<double> number_of(const toml::table& t, const char* key) {
  const toml::node* n = t.get(key);
  if (n == nullptr) return std::nullopt;
  if (const auto v = n->value<double>()) return *v;
  return std::nullopt;
}

void add_material(const io::Section& m, StrengthReduction& out) {
  const std::string model = m.string("model");
  const toml::table& t = m.raw();
  MaterialStrength s;
  s.table = m.path();
  s.model = model;
  auto divide = [&](const char* key) {
    if (const auto v = number_of(t, key)) s.divided.emplace_back(key, *v);
  };
  if (model == "elastic") {
    out.unreduced.push_back(m.path());
    return;
  }
  if (model == "perzyna_von_mises") {
    divide("cohesion");
    divide("yield_stress");
    divide("hardening_modulus");
    divide("residual_yield_stress");  // its default, 0.1 Y0, follows Y0 by itself
  } else if (model == "perzyna_drucker_prager" || model == "perzyna_mohr_coulomb") {
    divide("cohesion");
    divide("hardening_modulus");
    divide("residual_cohesion");  // default 0.1 c0: follows c0
    s.friction_angle = number_of(t, "friction_angle");
    s.dilatancy = number_of(t, "dilatancy");
  } else {
    m.fail("model", fmt::format("rktsph fos: no strength reduction is defined for the model '{}' (its strength "
                                "comes from the preconsolidation pressure and M, not from a cohesion or a "
                                "friction angle); strength reduction needs perzyna_von_mises, "
                                "perzyna_drucker_prager or perzyna_mohr_coulomb",
                                model));
  }
  out.materials.push_back(std::move(s));
}

}  // namespace

StrengthReduction read_strength(const CaseDocument& doc) {
  StrengthReduction out;
  const io::Section root(doc.table, "", doc.file_label);
  if (root.has("material")) {
    add_material(root.table("material"), out);
  } else {
    const io::Section ms = root.table("materials");
    for (const std::string& name : ms.keys()) add_material(ms.table(name), out);
  }
  if (out.materials.empty()) {
    const std::string table = out.unreduced.empty() ? "material" : out.unreduced.front();
    throw InputError(fmt::format("{}: rktsph fos: no material has a strength to reduce (every material is "
                                 "elastic); strength reduction needs a viscoplastic material with a cohesion",
                                 io::Section(doc.table, "", doc.file_label).where(table)));
  }
  return out;
}

FosTable read_fos_table(const CaseDocument& doc) {
  FosTable f;
  const io::Section root(doc.table, "", doc.file_label);
  f.where = root.where("fos");
  const auto s = root.optional_table("fos");
  if (!s) return f;
  const std::string mode = s->string("mode", "strength");
  if (mode == "load") {
    f.mode = FactorMode::load;
  } else if (mode != "strength") {
    s->fail("mode", fmt::format("unknown mode '{}': \"strength\" (the factor of safety by strength reduction) or "
                                "\"load\" (the load factor of the collapse load)",
                                mode));
  }
  if (s->has("load_functions")) {
    if (f.mode != FactorMode::load) {
      s->fail("load_functions", "the time functions of the loads are scaled only with mode = \"load\"");
    }
    f.load_functions = s->strings("load_functions");
    s->require(!f.load_functions.empty(), "load_functions", "name at least one time function");
  } else if (f.mode == FactorMode::load) {
    s->fail("mode",
            "mode = \"load\" needs load_functions: the names of the [functions.NAME] tables whose loads the "
            "factor multiplies, e.g. load_functions = [\"load\"]");
  }
  if (s->has("monitor")) {
    const toml::node* n = s->raw().get("monitor");
    if (n->is_string()) {
      f.monitor_probe = s->string("monitor");
    } else {
      f.monitor_point = s->numbers("monitor");
    }
  }
  if (s->has("direction")) {
    std::vector<double> d = s->numbers("direction");
    double norm = 0.0;
    for (double v : d) norm += v * v;
    norm = std::sqrt(norm);
    s->require(norm > 0.0, "direction", "the direction of the monitored displacement must not be zero");
    for (double& v : d) v /= norm;
    f.direction = d;
  }
  if (s->has("length")) f.length = s->positive("length");
  // Each rule has its own keys: a key of the other mode is a mistake, said as such.
  if (f.mode == FactorMode::load) {
    f.window = s->positive("window", 1.0);
    for (const char* key : {"hold", "rate_independent"}) {
      if (s->has(key)) {
        s->fail(key, "a strength-reduction key: the load factor keeps the case's materials and classifies the "
                     "last fos.window seconds of each trial (docs/fos.md, \"The load factor\")");
      }
    }
  } else {
    if (s->has("window")) {
      s->fail("window", "the load factor's classification window: a strength-reduction trial is judged over the "
                        "hold that follows time.end, fos.hold (s; docs/fos.md, \"The classification\")");
    }
    if (s->has("hold")) f.hold = s->positive("hold");
    f.rate_independent = s->boolean("rate_independent", true);
  }
  const std::string kinetic = s->string("kinetic", "auto");
  if (kinetic == "stress_points" || kinetic == "nodes") {
    f.kinetic_of_stress_points = kinetic == "stress_points";
  } else if (kinetic != "auto") {
    s->fail("kinetic", fmt::format("unknown kinetic energy '{}': \"auto\", \"nodes\" or \"stress_points\"", kinetic));
  }
  f.search.tolerance = s->positive("tolerance", f.search.tolerance);
  s->require(f.search.tolerance < 1.0, "tolerance",
             fmt::format("the relative tolerance on F must be below 1, got {}", f.search.tolerance));
  const auto trials = s->integer("max_trials", f.search.max_trials);
  s->require(trials >= 2 && trials <= 200, "max_trials", fmt::format("must lie in [2, 200], got {}", trials));
  f.search.max_trials = static_cast<int>(trials);
  f.search.growth = s->number("growth", f.search.growth);
  s->require(f.search.growth > 1.0 && f.search.growth <= 10.0, "growth",
             fmt::format("the expansion factor must lie in (1, 10], got {}", f.search.growth));
  s->finish();
  return f;
}

LoadScaling read_load_scaling(const CaseDocument& doc, const FosTable& table) {
  LoadScaling out;
  const io::Section root(doc.table, "", doc.file_label);
  const auto functions = root.optional_table("functions");
  for (const std::string& name : table.load_functions) {
    if (!functions || !functions->has(name)) {
      const std::vector<std::string> names = functions ? functions->keys() : std::vector<std::string>{};
      root.table("fos").fail(
          "load_functions",
          fmt::format("no time function '{}' in the case (its functions: {}); a load to be scaled needs a "
                      "[functions.NAME] table and `function = \"NAME\"` on its [[boundary]] entries",
                      name, names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "))));
    }
    const io::Section f = functions->table(name);
    const double scale = number_of(f.raw(), "scale").value_or(1.0);
    out.functions.emplace_back("functions." + name, scale);
  }
  return out;
}

namespace {

template <int Dim>
Monitor resolve(const CaseDocument& doc, const FosTable& f) {
  const CaseSetup<Dim> setup = read_case<Dim>(doc);
  const Simulation<Dim> solver(setup);
  const auto& x = solver.nodes().position;
  const io::Section root(doc.table, "", doc.file_label);
  const auto fos_table = root.optional_table("fos");
  auto fail = [&](const char* key, const std::string& message) {
    if (fos_table) fos_table->fail(key, message);
    throw InputError(fmt::format("{}: {}", root.where(), message));
  };
  Monitor m;
  m.window = f.window;
  // "auto": V2's held trials keep a nodal kinetic energy above 1e-2 of its peak while the
  // material is at rest (docs/fos.md, "Which kinetic energy"), so they read the stress points'.
  const bool stress_points = f.kinetic_of_stress_points.value_or(setup.version == "v2");
  m.kinetic_column = stress_points ? "kinetic_stress_points" : "kinetic";
  m.spacing = setup.dx;
  m.smoothing_length = setup.smoothing_length();
  if (f.mode == FactorMode::load && !(f.window < setup.end_time)) {
    fail("window", fmt::format("the classification window ({} s) must be shorter than time.end ({} s)", f.window,
                               setup.end_time));
  }
  Vec<Dim> target = Vec<Dim>::Zero();
  if (f.monitor_probe) {
    const auto p = std::find_if(setup.probes.begin(), setup.probes.end(),
                                [&](const ProbeSpec& q) { return q.name == *f.monitor_probe; });
    if (p == setup.probes.end()) {
      std::vector<std::string> names;
      for (const ProbeSpec& q : setup.probes) names.push_back(q.name);
      fail("monitor", fmt::format("no probe named '{}' in the case (its probes: {})", *f.monitor_probe,
                                  names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "))));
    }
    for (int d = 0; d < Dim; ++d) target[d] = p->position[static_cast<std::size_t>(d)];
    m.source = fmt::format("probe '{}'", *f.monitor_probe);
  } else if (f.monitor_point) {
    if (static_cast<int>(f.monitor_point->size()) != Dim) {
      fail("monitor", fmt::format("a point of {} coordinates in a {}D case", f.monitor_point->size(), Dim));
    }
    for (int d = 0; d < Dim; ++d) target[d] = (*f.monitor_point)[static_cast<std::size_t>(d)];
    m.source = "point";
  } else {
    // The default: the crest of a face that looks towards +x, the node of the top row (largest
    // last coordinate) with the largest x; in 3D the crest is a line along y, and the node in
    // the middle of it is taken (the one nearest the crest nodes' mean).
    const double tol = 1e-6 * setup.dx;
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& p : x) top = std::max(top, p[Dim - 1]);
    double best = -std::numeric_limits<double>::infinity();
    for (const auto& p : x) {
      if (p[Dim - 1] >= top - tol) best = std::max(best, p[0]);
    }
    Vec<Dim> mean = Vec<Dim>::Zero();
    int on_crest = 0;
    for (const auto& p : x) {
      if (p[Dim - 1] >= top - tol && p[0] >= best - tol) {
        mean += p;
        ++on_crest;
      }
    }
    mean /= static_cast<double>(on_crest);
    double closest = std::numeric_limits<double>::infinity();
    for (const auto& p : x) {
      if (p[Dim - 1] >= top - tol && p[0] >= best - tol && (p - mean).norm() < closest) {
        closest = (p - mean).norm();
        target = p;
      }
    }
    m.source = Dim == 3 ? "default: the crest (top row, largest x, middle of the crest line)"
                        : "default: the crest (top row, largest x)";
  }
  Index nearest = 0;
  double dist = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < solver.nodes().size(); ++i) {
    const double d = (x[static_cast<std::size_t>(i)] - target).norm();
    if (d < dist) {
      dist = d;
      nearest = i;
    }
  }
  // As for a probe (app/run_loop.cpp): farther than half a cell diagonal is off the body.
  if (dist > 0.5 * std::sqrt(static_cast<double>(Dim)) * setup.dx + 1e-9) {
    std::vector<double> t(target.data(), target.data() + Dim);
    fail("monitor", fmt::format("the monitored point [{}] is not on the body (the nearest node is {:.4g} m away)",
                                fmt::join(t, ", "), dist));
  }
  const auto& p = x[static_cast<std::size_t>(nearest)];
  m.position.assign(p.data(), p.data() + Dim);
  if (f.direction) {
    if (static_cast<int>(f.direction->size()) != Dim) {
      fail("direction", fmt::format("a direction of {} components in a {}D case", f.direction->size(), Dim));
    }
    m.direction = *f.direction;
  } else {
    m.direction.assign(static_cast<std::size_t>(Dim), 0.0);
    m.direction[0] = 1.0;
  }
  if (f.length) {
    m.length = *f.length;
  } else {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& q : x) {
      lo = std::min(lo, q[Dim - 1]);
      hi = std::max(hi, q[Dim - 1]);
    }
    m.length = hi - lo;
    if (!(m.length > 0.0)) fail("length", "the body has no height: give fos.length (m)");
  }
  // The hold of a strength-reduction trial (app/fos_criterion.hpp): after the case's time.end,
  // by default kHoldTimeScales time scales sqrt(L/g) of the body; without gravity the case's own
  // duration, the time its author gave the loads to settle.
  m.hold_start = setup.end_time;
  const double g = setup.gravity.norm();
  m.time_scale = g > 0.0 ? std::sqrt(m.length / g) : 0.0;
  m.hold = f.hold.value_or(g > 0.0 ? kHoldTimeScales * m.time_scale : setup.end_time);
  return m;
}

}  // namespace

Monitor resolve_monitor(const CaseDocument& doc, const FosTable& table) {
  const int dim = case_dimension(doc);
  if (dim == 1) return resolve<1>(doc, table);
  if (dim == 3) return resolve<3>(doc, table);
  return resolve<2>(doc, table);
}

}  // namespace rktsph::fos
