// A case file as a TOML document: parsing, the command-line overrides (--set key=value), the
// dimension of space, and the time-function tables (docs/case-format.md).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
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

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string trimmed(const std::string& s) {
  std::size_t a = 0, z = s.size();
  while (a < z && is_space(s[a])) ++a;
  while (z > a && is_space(s[z - 1])) --z;
  return s.substr(a, z - a);
}

// Byte offset in `text` of a source position of the document "v = " + text (toml++ counts
// lines from 1 and columns in code points from 1).
std::size_t offset_of(const std::string& text, const toml::source_position& pos) {
  const std::string doc = "v = " + text;
  std::size_t i = 0;
  for (toml::source_index line = 1; line < pos.line && i < doc.size(); ++i) {
    if (doc[i] == '\n') ++line;
  }
  for (toml::source_index col = 1; col < pos.column && i < doc.size(); ++col) {
    ++i;
    while (i < doc.size() && (static_cast<unsigned char>(doc[i]) & 0xC0u) == 0x80u) ++i;  // UTF-8 continuation
  }
  return i < 4 ? 0 : std::min(i - 4, text.size());
}

// The document "v = text" when it holds exactly one value with nothing but blanks after it.
std::optional<toml::table> parse_whole_value(const std::string& text, std::string* rest) {
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    return std::nullopt;
  }
  const toml::node* v = parsed.get("v");
  const std::string after = text.substr(offset_of(text, v->source().end));
  if (parsed.size() != 1 || !trimmed(after).empty()) {
    if (rest != nullptr) *rest = trimmed(after);
    return std::nullopt;
  }
  return parsed;
}

}  // namespace

toml::table parse_override_value(const std::string& label, const std::string& text) {
  // One TOML value (a number, a quoted string, true/false, an array, an inline table) and nothing
  // after it; or a bare word, which becomes a string (--set solver.version=v3).
  if (trimmed(text).empty()) {
    throw InputError(fmt::format("{}: no value after '=' (give a string as '\"\"')", label));
  }
  std::string rest;
  if (auto parsed = parse_whole_value(text, &rest)) return std::move(*parsed);
  if (!rest.empty()) {
    throw InputError(
        fmt::format("{}: text after the value: '{}' (a --set value is one TOML value; quote the whole "
                    "text to give a string)",
                    label, rest));
  }
  // Not TOML. Text that starts like a number, a quoted string, an array or a table and holds a
  // valid value followed by more text (1.0abc, "v3"x, [1, 2]x) is a typing error, not a word.
  const std::string t = trimmed(text);
  const char c0 = t.front();
  const bool value_like = (c0 >= '0' && c0 <= '9') || c0 == '+' || c0 == '-' || c0 == '.' || c0 == '"' || c0 == '\'' ||
                          c0 == '[' || c0 == '{';
  if (value_like) {
    for (std::size_t k = t.size() - 1; k >= 1; --k) {
      if (parse_whole_value(t.substr(0, k), nullptr)) {
        throw InputError(fmt::format("{}: '{}' is a value but '{}' follows it (quote the whole text to give a string)",
                                     label, trimmed(t.substr(0, k)), trimmed(t.substr(k))));
      }
    }
    if (c0 == '"' || c0 == '\'' || c0 == '[' || c0 == '{') {
      throw InputError(fmt::format("{}: '{}' is not a valid TOML value", label, t));
    }
  }
  return toml::table{{"v", text}};
}

void apply_override(toml::table& root, const std::string& assignment, const std::string& file) {
  const std::string label = fmt::format("{}: --set '{}'", file, assignment);
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError(fmt::format("{}: expected key=value, e.g. --set material.E=2.5e7", label));
  }
  const std::string key = assignment.substr(0, eq);
  const auto parts = split(key, '.');
  for (const std::string& p : parts) {
    if (trimmed(p).empty() || trimmed(p) != p) {
      throw InputError(fmt::format("{}: the key '{}' has an empty or blank-padded part", label, key));
    }
  }
  const toml::table parsed = parse_override_value(label, assignment.substr(eq + 1));
  auto defined_at = [](const toml::node& n) {
    const auto line = n.source().begin.line;
    return line > 0 ? fmt::format(" (line {})", line) : std::string();
  };
  toml::node* cur = &root;
  std::string path;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& p = parts[i];
    path += (path.empty() ? "" : ".") + p;
    if (auto* t = cur->as_table()) {
      toml::node* next = t->get(p);
      if (next == nullptr) {
        t->insert(p, toml::table{});
        next = t->get(p);
      }
      cur = next;
    } else if (auto* a = cur->as_array()) {
      if (p.find_first_not_of("0123456789") != std::string::npos || p.size() > 9) {
        throw InputError(fmt::format("{}: '{}' indexes an array and must be a whole number", label, p));
      }
      const std::size_t idx = std::stoul(p);
      if (idx >= a->size()) {
        throw InputError(fmt::format("{}: index {} is past the end of the array ({} entries)", label, idx, a->size()));
      }
      cur = a->get(idx);
    } else {
      throw InputError(fmt::format("{}: '{}' is a value{}, not a table", label, path, defined_at(*cur)));
    }
  }
  toml::table* parent = cur->as_table();
  if (parent == nullptr) {
    throw InputError(fmt::format("{}: '{}' is {}{}, not a table", label, path.empty() ? key : path,
                                 cur->is_array() ? "an array" : "a value", defined_at(*cur)));
  }
  parent->insert_or_assign(parts.back(), *parsed.get("v"));
}

CaseDocument load_case_document(const std::string& file, const std::vector<std::string>& overrides) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open the case file", file));
  std::stringstream buffer;
  buffer << in.rdbuf();
  CaseDocument doc = parse_case_document(buffer.str(), file, overrides);
  doc.directory = std::filesystem::path(file).parent_path().string();
  return doc;
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
  for (const auto& o : overrides) apply_override(doc.table, o, label);
  return doc;
}

int case_dimension(const CaseDocument& doc) {
  io::Section root(doc.table, "", doc.file_label);
  const io::Section g = root.table("geometry");
  const auto d = g.integer("dimension");
  if (d < 1 || d > 3) {
    g.fail("dimension", fmt::format("must be 1, 2 or 3, got {}", d));
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
