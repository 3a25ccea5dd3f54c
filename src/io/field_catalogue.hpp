#pragma once
// The one catalogue of output fields of a particle set (docs/output.md): the VTU frames, the
// probes and the validation snapshots all read the state through it. Each entry has a name,
// 1 or 3 components (vectors padded to 3 for ParaView) and a reader of its value at a
// particle; scalars() adds the single components of vectors ("vx", "uy") for the probes.
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
