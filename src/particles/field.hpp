#pragma once
// Per-particle fields by name (docs/architecture.md, "Particle state").
//
// A field is one array of `components` values of one type per particle, registered once on a
// particle set with a name, the names of its components and flags saying what it is for. The
// handle Field<T, N> it returns is the only way to reach the data, through a FieldView: the
// view alone knows the layout (N values per particle, contiguous), so no code outside it does
// index arithmetic on packed state. The same declaration list drives output, probes, sorting
// and (later) halo exchange and checkpoints.
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

/// What a field is for (bits).
enum FieldFlag : unsigned {
  kFieldOutput = 1u << 0,    // written to the VTU frames and available to probes
  kFieldEvolving = 1u << 1,  // part of the state: carried by sorting, halos and checkpoints
  kFieldScratch = 1u << 2,   // work space of a stage, rewritten every step
};

enum class FieldType { f64, u8, i64 };

template <class T>
constexpr FieldType field_type_of() {
  if constexpr (std::is_same_v<T, double>)
    return FieldType::f64;
  else if constexpr (std::is_same_v<T, std::uint8_t>)
    return FieldType::u8;
  else {
    static_assert(std::is_same_v<T, std::int64_t>, "fields hold double, std::uint8_t or std::int64_t");
    return FieldType::i64;
  }
}

/// What the values of a field are, for output: the field catalogue (io/field_catalogue.hpp)
/// writes a field by its kind, so that registering a field with kFieldOutput is all it takes
/// to have it in the frames and the probes.
enum class FieldKind {
  scalar,   // one value per component, each written by its component name
  vector,   // Dim components, written as a 3-vector named by the field (probes: the components)
  stress,   // the per-dimension stress layout: its components, and the invariants p and q
  history,  // material history variables: a component is a name of the HistoryLayout
};

struct FieldInfo {
  std::string name;
  FieldType type = FieldType::f64;
  int components = 1;
  std::vector<std::string> component_names;  // e.g. {"vx", "vy"}; empty for a scalar
  unsigned flags = 0;
  FieldKind kind = FieldKind::scalar;
};

/// Typed handle of a field of N values of T per particle. N = 0: the component count is fixed
/// when the field is registered (material history variables, whose count depends on the case).
template <class T, int N>
struct Field {
  int id = -1;
  bool valid() const { return id >= 0; }
};

/// Access to one field of one particle set. Row i is the contiguous block of components()
/// values of particle i.
template <class T, int N>
class FieldView {
 public:
  FieldView() = default;
  FieldView(T* data, Index size, int components) : data_(data), size_(size), components_(N > 0 ? N : components) {}

  static constexpr int kComponents = N;
  int components() const {
    if constexpr (N > 0) return N;
    return components_;
  }
  Index size() const { return size_; }
  /// First value of particle i (any integer index type).
  template <std::integral I>
  T* operator[](I i) const {
    return data_ + static_cast<std::size_t>(i) * static_cast<std::size_t>(components());
  }
  template <std::integral I>
  T& operator()(I i, int c) const {
    return (*this)[i][c];
  }
  /// The whole array: particle i's values start at data() + i * components().
  T* data() const { return data_; }

 private:
  T* data_ = nullptr;
  Index size_ = 0;
  int components_ = N;
};

template <class T, int N>
using ConstFieldView = FieldView<const T, N>;

/// A copy of every value of a field (tests, checkpoints).
template <class T, int N>
std::vector<std::remove_const_t<T>> values_of(FieldView<T, N> v) {
  return {v.data(), v.data() + static_cast<std::size_t>(v.size()) * static_cast<std::size_t>(v.components())};
}

/// A stress field in the per-dimension layout of core/types.hpp: (xx, yy, zz[, xy[, yz, xz]]).
template <int Dim>
class StressView {
 public:
  static constexpr int NS = kStressComponents<Dim>;
  StressView() = default;
  explicit StressView(FieldView<const double, NS> v) : v_(v) {}
  Index size() const { return v_.size(); }
  /// Component c of particle i (0 for a component that is identically zero in Dim).
  template <std::integral I>
  double operator()(I i, StressComponent c) const {
    const int s = stress_slot<Dim>(c);
    return s < 0 ? 0.0 : v_(i, s);
  }
  template <std::integral I>
  Sym6 sym6(I i) const {
    return to_sym6<Dim>(v_[i]);
  }
  template <std::integral I>
  Invariants invariants(I i) const {
    return rktsph::invariants(sym6(i));
  }
  template <std::integral I>
  const double* operator[](I i) const {
    return v_[i];
  }

 private:
  FieldView<const double, NS> v_;
};

/// A vector field of Dim components (velocity, displacement).
template <int Dim>
class VectorView {
 public:
  VectorView() = default;
  explicit VectorView(FieldView<const double, Dim> v) : v_(v) {}
  Index size() const { return v_.size(); }
  template <std::integral I>
  double operator()(I i, int axis) const {
    return v_(i, axis);
  }
  template <std::integral I>
  Vec<Dim> vec(I i) const {
    Vec<Dim> out;
    for (int d = 0; d < Dim; ++d) out[d] = v_(i, d);
    return out;
  }

 private:
  FieldView<const double, Dim> v_;
};

}  // namespace rktsph
