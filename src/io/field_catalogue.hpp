#pragma once
// The one catalogue of output fields of a particle set (docs/output.md): the VTU frames and the
// probes read the state through it. It is made from the set's field declarations: every field
// registered with kFieldOutput appears by its kind (a vector as a 3-vector and its components,
// a stress as its components and p, q, history variables by name), plus the derived total
// stresses where a pore pressure exists, and the material. Each entry has a name, 1 or 3
// components and a reader of its value at a particle.
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/vtu_writer.hpp"
#include "schemes/simulation.hpp"

namespace rktsph::io {

struct CatalogueField {
  std::string name;
  int components = 1;                           // 1 or 3
  std::function<double(Index i, int c)> value;  // c < components; 0 for padded components
};

/// A scalar reader, e.g. for a probe.
using ScalarField = std::function<double(Index i)>;

template <int Dim>
class FieldCatalogue {
 public:
  enum class Set { nodes, stress_points };
  FieldCatalogue(const Simulation<Dim>& simulation, Set set);

  /// The fields of a frame, in the order they are written.
  const std::vector<CatalogueField>& fields() const { return fields_; }
  /// All of them at the current state, for write_vtu.
  std::vector<PointField> extract() const;
  /// A scalar by name: a scalar field or one component of a vector ("vx").
  std::optional<ScalarField> scalar(std::string_view name) const;
  /// The names scalar() accepts, for error messages.
  std::vector<std::string> scalar_names() const;
  Index size() const { return size_; }

 private:
  struct Scalar {
    std::string name;
    ScalarField value;
  };
  Index size_ = 0;
  std::vector<CatalogueField> fields_;
  std::vector<Scalar> scalars_;
};

}  // namespace rktsph::io
