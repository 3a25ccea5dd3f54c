#include "io/field_catalogue.hpp"

#include <fmt/format.h>

namespace rktsph::io {

template <int Dim>
FieldCatalogue<Dim>::FieldCatalogue(const Simulation<Dim>& sim, Set set) {
  const bool nodes = set == Set::nodes;
  const ParticleSet<Dim>& particles = nodes ? sim.nodes() : sim.stress_points();
  size_ = particles.size();
  auto vector = [&](std::string name, const char* prefix, VectorView<Dim> v) {
    fields_.push_back({std::move(name), 3, [v](Index i, int c) { return c < Dim ? v(i, c) : 0.0; }});
    for (int d = 0; d < Dim; ++d) {
      scalars_.push_back(
          {fmt::format("{}{}", prefix, kAxisNames[static_cast<std::size_t>(d)]), [v, d](Index i) { return v(i, d); }});
    }
  };
  auto scalar = [&](std::string name, ScalarField f) {
    fields_.push_back({name, 1, [f](Index i, int) { return f(i); }});
    scalars_.push_back({std::move(name), std::move(f)});
  };

  vector("velocity", "v", nodes ? sim.node_velocity() : sim.stress_point_velocity());
  if (nodes) vector("displacement", "u", sim.node_displacement());
  const StressView<Dim> stress = nodes ? sim.node_stress() : sim.stress_point_stress();
  for (std::size_t c = 0; c < 6; ++c) {
    const auto comp = static_cast<StressComponent>(c);
    if (stress_slot<Dim>(comp) < 0) continue;
    scalar(fmt::format("s{}", kStressComponentNames[c]), [stress, comp](Index i) { return stress(i, comp); });
  }
  scalar("p", [stress](Index i) { return stress.invariants(i).p; });
  scalar("q", [stress](Index i) { return stress.invariants(i).q; });
  for (const std::string& name : sim.history_layout().names()) {
    const HistoryView h = nodes ? sim.node_history(name) : sim.stress_point_history(name);
    scalar(name, [h](Index i) { return h(i); });
  }
  if (nodes && sim.saturated()) {
    // V3: pore pressure (compression positive) and the total stresses sigma' - p_w 1; the
    // stress fields above are effective stresses.
    const std::span<const double> pw = sim.node_pore_pressure();
    scalar("pw", [pw](Index i) { return pw[static_cast<std::size_t>(i)]; });
    for (std::size_t c = 0; c < 6; ++c) {
      const auto comp = static_cast<StressComponent>(c);
      if (stress_slot<Dim>(comp) < 0) continue;
      const bool normal = c < 3;
      scalar(fmt::format("total_s{}", kStressComponentNames[c]), [stress, comp, pw, normal](Index i) {
        return stress(i, comp) - (normal ? pw[static_cast<std::size_t>(i)] : 0.0);
      });
    }
  }
  const std::vector<int>* material = &particles.material;
  fields_.push_back({"material", 1, [material](Index i, int) { return (*material)[static_cast<std::size_t>(i)]; }});
}

template <int Dim>
std::vector<PointField> FieldCatalogue<Dim>::extract() const {
  std::vector<PointField> out;
  const auto n = static_cast<std::size_t>(size_);
  for (const CatalogueField& f : fields_) {
    PointField p{f.name, f.components, std::vector<double>(n * static_cast<std::size_t>(f.components))};
    for (Index i = 0; i < size_; ++i) {
      for (int c = 0; c < f.components; ++c) {
        p.values[static_cast<std::size_t>(i) * static_cast<std::size_t>(f.components) + static_cast<std::size_t>(c)] =
            f.value(i, c);
      }
    }
    out.push_back(std::move(p));
  }
  return out;
}

template <int Dim>
std::optional<ScalarField> FieldCatalogue<Dim>::scalar(std::string_view name) const {
  for (const Scalar& s : scalars_) {
    if (s.name == name) return s.value;
  }
  return std::nullopt;
}

template <int Dim>
std::vector<std::string> FieldCatalogue<Dim>::scalar_names() const {
  std::vector<std::string> out;
  for (const Scalar& s : scalars_) out.push_back(s.name);
  return out;
}

template class FieldCatalogue<1>;
template class FieldCatalogue<2>;
template class FieldCatalogue<3>;

}  // namespace rktsph::io
