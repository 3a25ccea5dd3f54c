// A case file as a TOML document: parsing, the command-line overrides (--set key=value), the
// dimension of space, and the time-function tables (docs/case-format.md).
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "io/section.hpp"

namespace rktsph {

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

// Apply one --set key=value: the value is read as a TOML value (a bare word becomes a string).
void apply_override(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError(fmt::format("--set '{}': expected key=value, e.g. --set material.E=2.5e7", assignment));
  }
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", text}};
  }
  const auto parts = split(key, '.');
  toml::node* cur = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& p = parts[i];
    if (auto* t = cur->as_table()) {
      toml::node* next = t->get(p);
      if (next == nullptr) {
        t->insert(p, toml::table{});
        next = t->get(p);
      }
      cur = next;
    } else if (auto* a = cur->as_array()) {
      std::size_t idx = 0;
      try {
        idx = std::stoul(p);
      } catch (...) {
        throw InputError(fmt::format("--set '{}': '{}' indexes an array and must be a number", assignment, p));
      }
      if (idx >= a->size()) {
        throw InputError(
            fmt::format("--set '{}': index {} is past the end of the array ({} "
                        "entries)",
                        assignment, idx, a->size()));
      }
      cur = a->get(idx);
    } else {
      throw InputError(fmt::format("--set '{}': '{}' is not a table", assignment, p));
    }
  }
  toml::table* parent = cur->as_table();
  if (parent == nullptr) {
    throw InputError(fmt::format("--set '{}': the parent of '{}' is not a table", assignment, parts.back()));
  }
  parent->insert_or_assign(parts.back(), *parsed.get("v"));
}

}  // namespace

CaseDocument load_case_document(const std::string& file, const std::vector<std::string>& overrides) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open the case file", file));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_case_document(buffer.str(), file, overrides);
}

CaseDocument parse_case_document(const std::string& text, const std::string& label,
                                 const std::vector<std::string>& overrides) {
  CaseDocument doc;
  doc.file = label;
  doc.file_label = std::make_shared<const std::string>(label);
  try {
    doc.table = toml::parse(text, label);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}, line {}: not valid TOML: {}", label, e.source().begin.line, e.description()));
  }
  for (const auto& o : overrides) apply_override(doc.table, o);
  return doc;
}

int case_dimension(const CaseDocument& doc) {
  io::Section root(doc.table, "", doc.file_label);
  const io::Section g = root.table("geometry");
  const auto d = g.integer("dimension");
  if (d != 1 && d != 2) {
    g.fail("dimension", fmt::format("must be 1 or 2 (3D is not available yet), got {}", d));
  }
  return static_cast<int>(d);
}

TimeFunction read_time_function(const io::Section& s) {
  TimeFunction f;
  const std::string type = s.string("type");
  f.value = s.number("scale", 1.0);
  if (type == "constant") {
    f.kind = TimeFunction::Kind::constant;
  } else if (type == "step") {
    f.kind = TimeFunction::Kind::step;
    f.start = s.non_negative("start", 0.0);
  } else if (type == "ramp" || type == "smoothstep") {
    f.kind = type == "ramp" ? TimeFunction::Kind::ramp : TimeFunction::Kind::smoothstep;
    f.start = s.non_negative("start", 0.0);
    f.duration = s.positive("duration");
  } else if (type == "sine") {
    f.kind = TimeFunction::Kind::sine;
    f.offset = s.number("offset", 0.0);
    f.amplitude = s.number("amplitude", 1.0);
    f.frequency = s.positive("frequency");
    f.phase = s.number("phase", 0.0);
    f.rise_time = s.non_negative("rise_time", 0.0);
  } else if (type == "table") {
    f.kind = TimeFunction::Kind::table;
    f.times = s.numbers("times");
    f.values = s.numbers("values");
    s.require(!f.times.empty(), "times", "needs at least one point");
    s.require(f.times.size() == f.values.size(), "values",
              fmt::format("must have as many entries as 'times' ({}), got {}", f.times.size(), f.values.size()));
    for (std::size_t i = 1; i < f.times.size(); ++i) {
      s.require(f.times[i] > f.times[i - 1], "times", "must be strictly increasing");
    }
  } else {
    s.fail("type", fmt::format("unknown time function type '{}' (known: constant, step, ramp, "
                               "smoothstep, sine, table)",
                               type));
  }
  s.finish();
  return f;
}

}  // namespace rktsph
