#pragma once
// The state of a run as named arrays, for checkpoints (io/checkpoint.hpp): particle fields,
// the clock, the stages' own state, the run loop's output bookkeeping. Keys are paths
// ("nodes/velocity", "clock/time"); values are arrays of double, int64 or bytes (strings).
// The archive is what the HDF5 file holds, one dataset per key; its checksum covers every key
// and value, so a damaged file is recognised on reading.
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph::io {

class StateArchive {
 public:
  using Value = std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::uint8_t>>;

  void put(const std::string& key, std::vector<double> v) { values_[key] = std::move(v); }
  void put(const std::string& key, std::vector<std::int64_t> v) { values_[key] = std::move(v); }
  void put(const std::string& key, std::vector<std::uint8_t> v) { values_[key] = std::move(v); }
  void put(const std::string& key, double v) { values_[key] = std::vector<double>{v}; }
  void put_integer(const std::string& key, std::int64_t v) { values_[key] = std::vector<std::int64_t>{v}; }
  void put_text(const std::string& key, const std::string& text) {
    values_[key] = std::vector<std::uint8_t>(text.begin(), text.end());
  }

  bool has(const std::string& key) const { return values_.count(key) != 0; }
  const std::vector<double>& doubles(const std::string& key) const { return get<std::vector<double>>(key); }
  const std::vector<std::int64_t>& integers(const std::string& key) const {
    return get<std::vector<std::int64_t>>(key);
  }
  const std::vector<std::uint8_t>& bytes(const std::string& key) const { return get<std::vector<std::uint8_t>>(key); }
  double number(const std::string& key) const { return one(doubles(key), key); }
  std::int64_t integer(const std::string& key) const { return one(integers(key), key); }
  std::string text(const std::string& key) const {
    const auto& b = bytes(key);
    return {b.begin(), b.end()};
  }

  const std::map<std::string, Value>& values() const { return values_; }
  std::map<std::string, Value>& values() { return values_; }

  /// A 64-bit hash of every key and value, in key order: FNV-1a over 8-byte words (then the
  /// tail bytes), which reads a checkpoint of 10^5 particles in a few milliseconds.
  std::uint64_t checksum() const {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    auto mix = [&](const void* data, std::size_t n) {
      const auto* p = static_cast<const unsigned char*>(data);
      std::size_t i = 0;
      for (; i + 8 <= n; i += 8) {
        std::uint64_t w;
        std::memcpy(&w, p + i, 8);
        h = (h ^ w) * 0x100000001b3ULL;
        h ^= h >> 29;
      }
      for (; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
    };
    for (const auto& [key, value] : values_) {
      mix(key.data(), key.size());
      std::visit(
          [&](const auto& v) {
            const std::uint64_t n = v.size();
            mix(&n, sizeof(n));
            mix(v.data(), v.size() * sizeof(v[0]));
          },
          value);
    }
    return h;
  }

 private:
  template <class T>
  const T& get(const std::string& key) const {
    const auto it = values_.find(key);
    if (it == values_.end()) throw SolverError(fmt::format("the checkpoint has no '{}'", key));
    const T* v = std::get_if<T>(&it->second);
    if (v == nullptr) throw SolverError(fmt::format("the checkpoint's '{}' has another type", key));
    return *v;
  }
  template <class T>
  static T one(const std::vector<T>& v, const std::string& key) {
    if (v.size() != 1) throw SolverError(fmt::format("the checkpoint's '{}' is not one value", key));
    return v[0];
  }

  std::map<std::string, Value> values_;
};

}  // namespace rktsph::io
