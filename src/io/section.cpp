#include "io/section.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rktsph::io {

Section::Section(const toml::table& table, std::string path, std::shared_ptr<const std::string> file)
    : table_(&table), path_(std::move(path)), file_(std::move(file)) {}

std::string Section::key_path(std::string_view key) const {
  if (path_.empty()) return std::string(key);
  if (key.empty()) return path_;
  return fmt::format("{}.{}", path_, key);
}

std::string Section::location(const toml::node* n) const {
  const auto line = n != nullptr ? n->source().begin.line : 0u;
  if (line == 0) return fmt::format("{} (value set on the command line)", *file_);
  return fmt::format("{}, line {}", *file_, line);
}

std::string Section::where(std::string_view key) const {
  const toml::node* n = key.empty() ? static_cast<const toml::node*>(table_) : node(key);
  if (n == nullptr) n = table_;
  const std::string k = key_path(key);
  if (k.empty()) return location(n);
  return fmt::format("{}, key '{}'", location(n), k);
}

void Section::fail(std::string_view key, std::string_view message) const {
  throw InputError(fmt::format("{}: {}", where(key), message));
}

const toml::node* Section::node(std::string_view key) const { return table_->get(key); }

bool Section::has(std::string_view key) const { return node(key) != nullptr; }

const toml::node& Section::required(std::string_view key) const {
  consumed_.insert(std::string(key));
  const toml::node* n = node(key);
  if (n == nullptr) {
    throw InputError(fmt::format("{}: missing required key '{}'", location(table_), key_path(key)));
  }
  return *n;
}

namespace {
std::string_view type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::table:
      return "a table";
    default:
      return "a date or time";
  }
}
// A float, or an integer as the nearest double. (toml++'s value<double>() gives nothing for an
// integer that a double does not hold exactly, such as 9223372036854775807.)
std::optional<double> number_value(const toml::node& n) {
  if (n.is_floating_point()) return n.as_floating_point()->get();
  if (n.is_integer()) return static_cast<double>(n.as_integer()->get());
  return std::nullopt;
}

std::string magnitude_message(double v) {
  return fmt::format(
      "{} is beyond {:.0e} in magnitude: not a physical value in SI units (products and squares of "
      "such numbers overflow)",
      v, Section::kMaxMagnitude);
}

}  // namespace

double Section::number(std::string_view key) const {
  const toml::node& n = required(key);
  if (auto v = number_value(n)) {
    if (!std::isfinite(*v)) fail(key, "must be a finite number");
    if (!(std::abs(*v) <= kMaxMagnitude)) fail(key, magnitude_message(*v));
    return *v;
  }
  fail(key, fmt::format("must be a number, got {}", type_name(n)));
}

double Section::number_or_infinity(std::string_view key) const {
  const toml::node& n = required(key);
  if (n.is_string()) {
    if (n.value<std::string_view>().value() == "inf") return std::numeric_limits<double>::infinity();
    fail(key, fmt::format("must be a number or \"inf\", got the string \"{}\"", n.value<std::string_view>().value()));
  }
  if (auto v = number_value(n); v && std::isinf(*v) && *v > 0.0) return *v;
  return number(key);
}

double Section::number(std::string_view key, double fallback) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return fallback;
  }
  return number(key);
}

std::optional<double> Section::optional_number(std::string_view key) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return std::nullopt;
  }
  return number(key);
}

std::int64_t Section::integer(std::string_view key) const {
  const toml::node& n = required(key);
  if (!n.is_integer()) fail(key, fmt::format("must be an integer, got {}", type_name(n)));
  return n.value<std::int64_t>().value();
}

std::int64_t Section::integer(std::string_view key, std::int64_t fallback) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return fallback;
  }
  return integer(key);
}

std::string Section::string(std::string_view key) const {
  const toml::node& n = required(key);
  if (!n.is_string()) fail(key, fmt::format("must be a string, got {}", type_name(n)));
  return std::string(n.value<std::string_view>().value());
}

std::string Section::string(std::string_view key, std::string_view fallback) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return std::string(fallback);
  }
  return string(key);
}

bool Section::boolean(std::string_view key, bool fallback) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return fallback;
  }
  const toml::node& n = required(key);
  if (!n.is_boolean()) fail(key, fmt::format("must be true or false, got {}", type_name(n)));
  return n.value<bool>().value();
}

std::vector<double> Section::numbers(std::string_view key) const {
  const toml::node& n = required(key);
  const toml::array* arr = n.as_array();
  if (arr == nullptr) fail(key, fmt::format("must be an array of numbers, got {}", type_name(n)));
  std::vector<double> out;
  for (const toml::node& item : *arr) {
    const std::optional<double> value = number_value(item);
    if (!value) fail(key, fmt::format("must be an array of numbers, but an element is {}", type_name(item)));
    const double v = *value;
    if (!std::isfinite(v)) fail(key, "must hold finite numbers");
    if (!(std::abs(v) <= kMaxMagnitude)) fail(key, magnitude_message(v));
    out.push_back(v);
  }
  return out;
}

namespace {
// The rows of an array of arrays of `width` numbers; `fail` reports with a message.
std::vector<std::vector<double>> rows_of(const toml::node& n, std::size_t width, std::string_view what,
                                         const Section& s, std::string_view key) {
  auto fail = [&](std::string_view m) { s.fail(key, m); };
  const toml::array* arr = n.as_array();
  if (arr == nullptr) s.fail(key, fmt::format("must be {}, got {}", what, type_name(n)));
  std::vector<std::vector<double>> out;
  for (const toml::node& row : *arr) {
    const toml::array* r = row.as_array();
    if (r == nullptr || r->size() != width) {
      s.fail(key, fmt::format("must be {}; element {} is {}", what, out.size(),
                       r == nullptr ? std::string(type_name(row)) : fmt::format("an array of {} values", r->size())));
    }
    std::vector<double> values;
    for (const toml::node& item : *r) {
      const std::optional<double> value = number_value(item);
      if (!value) fail(fmt::format("must be {}, but element {} holds {}", what, out.size(), type_name(item)));
      if (!std::isfinite(*value)) fail("must hold finite numbers");
      if (!(std::abs(*value) <= Section::kMaxMagnitude)) fail(magnitude_message(*value));
      values.push_back(*value);
    }
    out.push_back(std::move(values));
  }
  return out;
}
}  // namespace

std::vector<std::vector<double>> Section::number_rows(std::string_view key, std::size_t width) const {
  const std::string what = fmt::format("an array of [{}] points", width == 2 ? "x, y" : "x, y, z");
  return rows_of(required(key), width, what, *this, key);
}

std::vector<std::vector<std::vector<double>>> Section::number_row_lists(std::string_view key,
                                                                       std::size_t width) const {
  const toml::node& n = required(key);
  const toml::array* arr = n.as_array();
  if (arr == nullptr) fail(key, fmt::format("must be an array of arrays of points, got {}", type_name(n)));
  std::vector<std::vector<std::vector<double>>> out;
  for (const toml::node& list : *arr) {
    const std::string what =
        fmt::format("an array of arrays of [{}] points (element {})", width == 2 ? "x, y" : "x, y, z", out.size());
    out.push_back(rows_of(list, width, what, *this, key));
  }
  return out;
}

std::vector<std::string> Section::strings(std::string_view key) const {
  const toml::node& n = required(key);
  const toml::array* arr = n.as_array();
  if (arr == nullptr) fail(key, fmt::format("must be an array of strings, got {}", type_name(n)));
  std::vector<std::string> out;
  for (const toml::node& item : *arr) {
    if (!item.is_string()) {
      fail(key, fmt::format("must be an array of strings, but an element is {}", type_name(item)));
    }
    out.emplace_back(item.value<std::string_view>().value());
  }
  return out;
}

double Section::positive(std::string_view key) const {
  const double v = number(key);
  if (!(v > 0.0)) fail(key, fmt::format("must be > 0, got {}", v));
  return v;
}

double Section::positive(std::string_view key, double fallback) const {
  const double v = number(key, fallback);
  if (!(v > 0.0)) fail(key, fmt::format("must be > 0, got {}", v));
  return v;
}

double Section::non_negative(std::string_view key, double fallback) const {
  const double v = number(key, fallback);
  if (!(v >= 0.0)) fail(key, fmt::format("must be >= 0, got {}", v));
  return v;
}

void Section::require(bool condition, std::string_view key, std::string_view message) const {
  if (!condition) fail(key, message);
}

Section Section::table(std::string_view key) const {
  const toml::node& n = required(key);
  const toml::table* t = n.as_table();
  if (t == nullptr) fail(key, fmt::format("must be a table, got {}", type_name(n)));
  return Section(*t, key_path(key), file_);
}

std::optional<Section> Section::optional_table(std::string_view key) const {
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return std::nullopt;
  }
  return table(key);
}

std::vector<Section> Section::tables(std::string_view key) const {
  std::vector<Section> out;
  if (!has(key)) {
    consumed_.insert(std::string(key));
    return out;
  }
  const toml::node& n = required(key);
  const toml::array* arr = n.as_array();
  if (arr == nullptr) {
    fail(key, fmt::format("must be an array of tables ([[{}]]), got {}", key_path(key), type_name(n)));
  }
  std::size_t i = 0;
  for (const toml::node& item : *arr) {
    const toml::table* t = item.as_table();
    if (t == nullptr) fail(key, "every element must be a table");
    out.emplace_back(*t, fmt::format("{}[{}]", key_path(key), i++), file_);
  }
  return out;
}

std::vector<std::string> Section::keys() const {
  std::vector<std::string> out;
  for (const auto& [k, v] : *table_) out.emplace_back(k.str());
  return out;
}

void Section::finish() const {
  for (const auto& [k, v] : *table_) {
    if (!consumed_.contains(k.str())) {
      std::vector<std::string> known(consumed_.begin(), consumed_.end());
      throw InputError(fmt::format("{}, key '{}': unknown key (this table accepts: {})", location(&v),
                                   key_path(k.str()), fmt::join(known, ", ")));
    }
  }
}

}  // namespace rktsph::io
