#pragma once
// Validated access to one table of a TOML case file.
//
// Every read names its key; every error names the file, the line and the full dotted key, and
// is raised as an InputError (exit status 2). A key that is present but never read is an
// unknown key: `finish()` reports it with the list of keys this table accepts, so a misspelt
// option is an error, never silently ignored.
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "core/error.hpp"

namespace rktsph::io {

class Section {
 public:
  /// Numbers are finite and at most this in magnitude: no quantity of a case in SI units comes
  /// near it (a modulus of 1e12 Pa, a time of 1e10 s), and squares of larger ones overflow.
  static constexpr double kMaxMagnitude = 1.0e100;

  Section(const toml::table& table, std::string path, std::shared_ptr<const std::string> file);

  /// Full dotted path of a key of this table, e.g. "material.E".
  std::string key_path(std::string_view key) const;
  /// "case.toml, line 12, key 'material.E'" (or the table itself when key is empty).
  std::string where(std::string_view key = {}) const;
  [[noreturn]] void fail(std::string_view key, std::string_view message) const;

  bool has(std::string_view key) const;

  double number(std::string_view key) const;
  double number(std::string_view key, double fallback) const;
  std::optional<double> optional_number(std::string_view key) const;
  /// A finite number, or +infinity written as TOML's `inf` or the string "inf" (a limit a model
  /// treats apart, e.g. a rate-independent material's fluidity).
  double number_or_infinity(std::string_view key) const;
  std::int64_t integer(std::string_view key) const;
  std::int64_t integer(std::string_view key, std::int64_t fallback) const;
  std::string string(std::string_view key) const;
  std::string string(std::string_view key, std::string_view fallback) const;
  bool boolean(std::string_view key, bool fallback) const;
  std::vector<double> numbers(std::string_view key) const;
  std::vector<std::string> strings(std::string_view key) const;
  /// An array of arrays of numbers, e.g. a polygon's vertices [[x, y], ...]; every inner array
  /// must have `width` numbers.
  std::vector<std::vector<double>> number_rows(std::string_view key, std::size_t width) const;
  /// An array of such arrays, e.g. a polygon's holes [[[x, y], ...], ...].
  std::vector<std::vector<std::vector<double>>> number_row_lists(std::string_view key, std::size_t width) const;

  /// Value checks: fail with a message naming the key when the condition does not hold.
  double positive(std::string_view key) const;
  double positive(std::string_view key, double fallback) const;
  double non_negative(std::string_view key, double fallback) const;
  void require(bool condition, std::string_view key, std::string_view message) const;

  Section table(std::string_view key) const;
  std::optional<Section> optional_table(std::string_view key) const;
  std::vector<Section> tables(std::string_view key) const;  // array of tables, may be empty
  /// Keys present in this table (to iterate over user-named entries such as functions).
  std::vector<std::string> keys() const;

  /// Error on any key that was never read. Call once all reads of the table are done.
  void finish() const;

  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  const toml::table& raw() const { return *table_; }

 private:
  const toml::node* node(std::string_view key) const;
  const toml::node& required(std::string_view key) const;
  std::string location(const toml::node* n) const;

  const toml::table* table_;
  std::string path_;
  std::shared_ptr<const std::string> file_;
  mutable std::set<std::string, std::less<>> consumed_;
};

}  // namespace rktsph::io
