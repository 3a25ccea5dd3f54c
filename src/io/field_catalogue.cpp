#include "io/field_catalogue.hpp"

#include <fmt/format.h>

namespace rktsph::io {

template <int Dim>
FieldCatalogue<Dim>::FieldCatalogue(const Simulation<Dim>& sim, Set set) {
  const ParticleSet<Dim>& particles = set == Set::nodes ? sim.nodes() : sim.stress_points();
  size_ = particles.size();
  auto scalar = [&](std::string name, ScalarField f) {
    fields_.push_back({name, 1, [f](Index i, int) { return f(i); }});
    scalars_.push_back({std::move(name), std::move(f)});
  };
  // Every field declared for output, by its kind (particles/field.hpp), in declaration order.
  std::optional<StressView<Dim>> stress;
  for (const FieldInfo& info : particles.fields()) {
    if ((info.flags & kFieldOutput) == 0 || info.type != FieldType::f64) continue;
    switch (info.kind) {
      case FieldKind::vector: {
        const VectorView<Dim> v(particles.view(particles.template find<double, Dim>(info.name)));
        fields_.push_back({info.name, 3, [v](Index i, int c) { return c < Dim ? v(i, c) : 0.0; }});
        for (int d = 0; d < Dim; ++d) {
          scalars_.push_back({info.component_names[static_cast<std::size_t>(d)], [v, d](Index i) { return v(i, d); }});
        }
        break;
      }
      case FieldKind::stress: {
        const StressView<Dim> s(particles.view(particles.template find<double, kStressComponents<Dim>>(info.name)));
        stress = s;
        for (int k = 0; k < kStressComponents<Dim>; ++k) {
          scalar(info.component_names[static_cast<std::size_t>(k)], [s, k](Index i) { return s[i][k]; });
        }
        scalar("p", [s](Index i) { return s.invariants(i).p; });
        scalar("q", [s](Index i) { return s.invariants(i).q; });
        break;
      }
      case FieldKind::history: {
        const HistoryLayout& layout = sim.history_layout();
        const auto values = particles.view(particles.template find<double, 0>(info.name));
        for (std::size_t k = 0; k < layout.names().size(); ++k) {
          const HistoryView h(values, layout, particles.material, static_cast<int>(k));
          scalar(layout.names()[k], [h](Index i) { return h(i); });
        }
        break;
      }
      case FieldKind::scalar: {
        const auto values = particles.view(particles.template find<double, 0>(info.name));
        for (int c = 0; c < info.components; ++c) {
          const std::string name = c < static_cast<int>(info.component_names.size())
                                       ? info.component_names[static_cast<std::size_t>(c)]
                                       : (info.components == 1 ? info.name : fmt::format("{}_{}", info.name, c));
          scalar(name, [values, c](Index i) { return values(i, c); });
        }
        // V3: with the pore pressure, the total stresses sigma' - p_w 1 (the stress fields are
        // effective stresses).
        if (info.name == "pore_pressure" && stress) {
          const StressView<Dim> s = *stress;
          for (std::size_t c = 0; c < 6; ++c) {
            const auto comp = static_cast<StressComponent>(c);
            if (stress_slot<Dim>(comp) < 0) continue;
            const bool normal = c < 3;
            scalar(fmt::format("total_s{}", kStressComponentNames[c]), [s, comp, values, normal](Index i) {
              return s(i, comp) - (normal ? values(i, 0) : 0.0);
            });
          }
        }
        break;
      }
    }
  }
  // V2: the density of the continuity equation (kg/m^3), which the step from the current state
  // follows (method-notes eq. (4.3.3)); constant in the schemes whose particles do not move.
  if (sim.setup().version == "v2") {
    const std::vector<double>* density = &particles.density;
    scalar("density", [density](Index i) { return (*density)[static_cast<std::size_t>(i)]; });
    // The particle's global id: V2 stores its particles sorted by cell and sorts them again as
    // they move, so a particle is followed from frame to frame by its id, not its place.
    const std::vector<std::int64_t>* ids = &particles.global_id;
    scalar("id", [ids](Index i) { return static_cast<double>((*ids)[static_cast<std::size_t>(i)]); });
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
