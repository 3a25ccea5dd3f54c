#pragma once
// A set of particles (docs/architecture.md, "Particle state"): the nodes and the stress points
// of the staggered scheme are two of them (method-notes §3.3).
//
// Every set has mutable positions, volumes, densities, materials and global ids, and holds
// the fields its schemes register by name (particles/field.hpp), one array per field. The
// first owned() particles belong to this process; the rest, [owned(), size()), is room for
// ghost copies of other processes' particles (a halo; none yet). Reordering (V2 sorts its sets
// by cell, neighbours/morton.hpp) goes through permute(), which carries every property and field.
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/types.hpp"
#include "particles/field.hpp"
#include "particles/permutation.hpp"

namespace rktsph {

template <int Dim>
class ParticleSet {
 public:
  explicit ParticleSet(std::string name = "particles") : name_(std::move(name)) {}

  // Properties of every particle (one entry each, all of length size()).
  std::vector<Vec<Dim>> position;       // m
  std::vector<double> volume;           // m^Dim (per unit thickness in 2D, per unit area in 1D)
  std::vector<double> density;          // kg/m^3
  std::vector<int> material;            // index into the case's materials
  std::vector<std::int64_t> global_id;  // the same particle on every process and after sorting

  const std::string& name() const { return name_; }
  void set_name(std::string name) { name_ = std::move(name); }
  Index size() const { return static_cast<Index>(position.size()); }
  Index owned() const { return owned_; }
  Index ghosts() const { return size() - owned_; }
  double mass(Index i) const { return volume[static_cast<std::size_t>(i)] * density[static_cast<std::size_t>(i)]; }

  /// Append an owned particle (generators; before any ghost is added). Fields get zeros.
  void add(const Vec<Dim>& x, double V, double rho, int mat) {
    if (ghosts() != 0) throw SolverError(fmt::format("{}: owned particles must come before the ghosts", name_));
    position.push_back(x);
    volume.push_back(V);
    density.push_back(rho);
    material.push_back(mat);
    global_id.push_back(static_cast<std::int64_t>(position.size()) - 1);
    ++owned_;
    for (Column& c : columns_) c.resize(position.size());
  }

  /// Replace every particle by new owned ones (re-seeding, particles/reseed.hpp): the properties
  /// given (all of one length), every field sized to the new count and zeroed. `replacements`
  /// sets the count of replacements (a checkpoint's); by default it grows by one.
  void replace(std::vector<Vec<Dim>> x, std::vector<double> V, std::vector<double> rho, std::vector<int> mat,
               std::vector<std::int64_t> ids, std::int64_t replacements = -1) {
    const std::size_t n = x.size();
    if (V.size() != n || rho.size() != n || mat.size() != n || ids.size() != n) {
      throw SolverError(fmt::format("{}: replacement properties of unequal lengths", name_));
    }
    position = std::move(x);
    volume = std::move(V);
    density = std::move(rho);
    material = std::move(mat);
    global_id = std::move(ids);
    owned_ = static_cast<Index>(n);
    replacements_ = replacements >= 0 ? replacements : replacements_ + 1;
    for (Column& c : columns_) {
      c.f64.clear();
      c.u8.clear();
      c.i64.clear();
      c.resize(n);
    }
  }

  /// How many times replace() has renewed the set (0 as made from the case).
  std::int64_t replacements() const { return replacements_; }

  /// Register a field (zero-initialised). N = 0 takes the component count from `components`.
  template <class T, int N>
  Field<T, N> add_field(std::string field_name, std::vector<std::string> component_names, unsigned flags,
                        int components = N, FieldKind kind = FieldKind::scalar) {
    if (find_id(field_name) >= 0) {
      throw SolverError(fmt::format("{}: the field '{}' is registered twice", name_, field_name));
    }
    Column c;
    c.info = {
        std::move(field_name), field_type_of<T>(), N > 0 ? N : components, std::move(component_names), flags, kind};
    c.resize(position.size());
    columns_.push_back(std::move(c));
    return Field<T, N>{static_cast<int>(columns_.size()) - 1};
  }

  /// The field named `field_name`, or an invalid handle if there is none. Throws if it exists
  /// with another type or component count.
  template <class T, int N>
  Field<T, N> find(std::string_view field_name) const {
    const int id = find_id(field_name);
    if (id < 0) return {};
    const FieldInfo& info = columns_[static_cast<std::size_t>(id)].info;
    if (info.type != field_type_of<T>() || (N > 0 && info.components != N)) {
      throw SolverError(fmt::format("{}: the field '{}' has another type or component count", name_, field_name));
    }
    return Field<T, N>{id};
  }
  bool has(std::string_view field_name) const { return find_id(field_name) >= 0; }

  template <class T, int N>
  FieldView<T, N> view(Field<T, N> f) {
    Column& c = column(f.id);
    return FieldView<T, N>(c.template data<T>(), size(), c.info.components);
  }
  template <class T, int N>
  FieldView<const T, N> view(Field<T, N> f) const {
    const Column& c = column(f.id);
    return FieldView<const T, N>(const_cast<Column&>(c).template data<T>(), size(), c.info.components);
  }

  /// Every value of field `id` (type-checked): the generic access of checkpoints and halos.
  template <class T>
  std::span<T> values(int id) {
    Column& c = column(id);
    if (c.info.type != field_type_of<T>())
      throw SolverError(fmt::format("{}: field '{}' has another type", name_, c.info.name));
    const auto n = static_cast<std::size_t>(size()) * static_cast<std::size_t>(c.info.components);
    return {c.template data<T>(), n};
  }
  template <class T>
  std::span<const T> values(int id) const {
    return const_cast<ParticleSet*>(this)->template values<T>(id);
  }

  /// The declarations, in registration order (output writes them in this order).
  std::vector<FieldInfo> fields() const {
    std::vector<FieldInfo> out;
    for (const Column& c : columns_) out.push_back(c.info);
    return out;
  }
  const FieldInfo& info(int id) const { return column(id).info; }

  /// A hash (FNV-1a) of the particles as they are now: positions, volumes, materials and ids,
  /// bit for bit. Taken when a set is made from a case, it identifies that case's particles
  /// after they have moved (checkpoints).
  std::uint64_t fingerprint() const {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, std::size_t n) {
      const auto* b = static_cast<const unsigned char*>(data);
      for (std::size_t k = 0; k < n; ++k) h = (h ^ b[k]) * 1099511628211ull;
    };
    for (const auto& x : position) mix(x.data(), sizeof(double) * Dim);
    mix(volume.data(), volume.size() * sizeof(double));
    mix(material.data(), material.size() * sizeof(int));
    mix(global_id.data(), global_id.size() * sizeof(std::int64_t));
    return h;
  }

  /// Bytes held by the properties and the fields whose flags intersect `flags` (all by default).
  std::size_t bytes(unsigned flags = ~0u) const {
    std::size_t b = position.size() * sizeof(Vec<Dim>) + (volume.size() + density.size()) * sizeof(double) +
                    material.size() * sizeof(int) + global_id.size() * sizeof(std::int64_t);
    for (const Column& c : columns_) {
      if ((c.info.flags & flags) != 0 || (c.info.flags == 0 && flags == ~0u)) b += c.bytes();
    }
    return b;
  }

  /// Reorder: particle k of the result is particle order[k] of this set (a permutation of
  /// [0, size())). Every property and field moves with its particle, in place: views and
  /// pointers into the arrays stay valid. Each array is copied once into a temporary (V2 sorts
  /// rarely, method-notes §3.8; no memory is held for it between sorts).
  void permute(const std::vector<Index>& order) {
    if (order.size() != position.size()) throw SolverError(fmt::format("{}: permutation of the wrong size", name_));
    permute_rows(position, order);
    permute_rows(volume, order);
    permute_rows(density, order);
    permute_rows(material, order);
    permute_rows(global_id, order);
    for (Column& c : columns_) {
      const auto n = static_cast<std::size_t>(c.info.components);
      permute_rows(c.f64, order, n);
      permute_rows(c.u8, order, n);
      permute_rows(c.i64, order, n);
    }
  }

 private:
  struct Column {
    FieldInfo info;
    std::vector<double> f64;
    std::vector<std::uint8_t> u8;
    std::vector<std::int64_t> i64;
    void resize(std::size_t particles) {
      const std::size_t n = particles * static_cast<std::size_t>(info.components);
      switch (info.type) {
        case FieldType::f64:
          f64.resize(n, 0.0);
          break;
        case FieldType::u8:
          u8.resize(n, 0);
          break;
        case FieldType::i64:
          i64.resize(n, 0);
          break;
      }
    }
    std::size_t bytes() const {
      return f64.size() * sizeof(double) + u8.size() * sizeof(std::uint8_t) + i64.size() * sizeof(std::int64_t);
    }
    template <class T>
    T* data() {
      if constexpr (std::is_same_v<std::remove_const_t<T>, double>)
        return f64.data();
      else if constexpr (std::is_same_v<std::remove_const_t<T>, std::uint8_t>)
        return u8.data();
      else
        return i64.data();
    }
  };

  int find_id(std::string_view field_name) const {
    for (std::size_t i = 0; i < columns_.size(); ++i) {
      if (columns_[i].info.name == field_name) return static_cast<int>(i);
    }
    return -1;
  }
  Column& column(int id) {
    if (id < 0 || id >= static_cast<int>(columns_.size())) throw SolverError(fmt::format("{}: no such field", name_));
    return columns_[static_cast<std::size_t>(id)];
  }
  const Column& column(int id) const { return const_cast<ParticleSet*>(this)->column(id); }

  std::string name_;
  Index owned_ = 0;
  std::int64_t replacements_ = 0;
  std::vector<Column> columns_;
};

}  // namespace rktsph
