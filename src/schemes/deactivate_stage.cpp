#include "schemes/deactivate_stage.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/state_archive.hpp"

namespace rktsph {

template <int Dim>
DeactivateOutside<Dim>::DeactivateOutside(StaggeredModel<Dim>& model) : m_(model) {
  const auto& box = *model.setup.domain_box;
  lo_ = box[0];
  hi_ = box[1];
  auto check = [&](const ParticleSet<Dim>& set, const char* what) {
    for (Index i = 0; i < set.size(); ++i) {
      const Vec<Dim>& x = set.position[static_cast<std::size_t>(i)];
      if (outside(x)) {
        std::string at;
        for (int d = 0; d < Dim; ++d) at += fmt::format("{}{:.6g}", d > 0 ? ", " : "", x[d]);
        throw InputError(
            fmt::format("{}: {} {} at ({}) lies outside the domain box (solver.domain_min / "
                        "domain_max) at the start; the box must contain the whole body",
                        model.setup.domain_where.empty() ? model.setup.file : model.setup.domain_where, what, i, at));
      }
    }
  };
  check(model.nodes, "node");
  check(model.stress_points, "stress point");
  active_nodes_ = m_.nodes.template add_field<double, 1>("active", {"active"}, kFieldOutput);
  active_stress_points_ = m_.stress_points.template add_field<double, 1>("active", {"active"}, kFieldOutput);
  mark_active(m_.nodes, active_nodes_, nodes_);
  mark_active(m_.stress_points, active_stress_points_, stress_points_);
  replacements_seen_ = m_.stress_points.replacements();
}

template <int Dim>
bool DeactivateOutside<Dim>::outside(const Vec<Dim>& x) const {
  for (int d = 0; d < Dim; ++d) {
    if (!(x[d] >= lo_[d] && x[d] <= hi_[d])) return true;  // a non-finite coordinate too
  }
  return false;
}

template <int Dim>
void DeactivateOutside<Dim>::mark_active(ParticleSet<Dim>& set, Field<double, 1> active,
                                         const std::vector<Frozen>& frozen) {
  // The output field only: the state is the frozen list (a re-seeding zeroes the set's fields).
  auto a = set.view(active);
  for (Index i = 0; i < set.size(); ++i) a(i, 0) = 1.0;
  for (const Frozen& f : frozen) a(f.index, 0) = 0.0;
}

template <int Dim>
template <int NS>
long DeactivateOutside<Dim>::sweep(ParticleSet<Dim>& set, Field<double, Dim> velocity, Field<double, NS> stress,
                                   Field<double, 1> active, std::vector<Frozen>& frozen) {
  auto v = set.view(velocity);
  auto s = set.view(stress);
  mark_active(set, active, frozen);
  auto a = set.view(active);
  // The frozen ones back where they were found, at rest (the step moved them by the gravity
  // of one step at most: they have no neighbours' stress, having no volume to carry it).
  for (const Frozen& f : frozen) {
    set.position[static_cast<std::size_t>(f.index)] = f.position;
    for (int d = 0; d < Dim; ++d) v(f.index, d) = 0.0;
  }
  long added = 0;
  for (Index i = 0; i < set.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    if (a(i, 0) == 0.0 || !outside(set.position[iu])) continue;
    mass_ += set.mass(i);
    set.volume[iu] = 0.0;  // no mass: out of every sum, and the continuity equation keeps it so
    for (int d = 0; d < Dim; ++d) v(i, d) = 0.0;
    for (int c = 0; c < s.components(); ++c) s(i, c) = 0.0;
    a(i, 0) = 0.0;
    frozen.push_back({i, set.position[iu]});
    ++added;
  }
  return added;
}

template <int Dim>
void DeactivateOutside<Dim>::run(const StepContext& c) {
  if (m_.stress_points.replacements() != replacements_seen_) {
    // Re-seeded from the nodes (whose frozen ones have no volume to deposit): a new set.
    stress_points_.clear();
    mark_active(m_.stress_points, active_stress_points_, stress_points_);
    replacements_seen_ = m_.stress_points.replacements();
  }
  const long nodes = sweep(m_.nodes, m_.fields.velocity, m_.fields.stress, active_nodes_, nodes_);
  const long points =
      sweep(m_.stress_points, m_.fields.sp_velocity, m_.fields.sp_stress, active_stress_points_, stress_points_);
  stress_points_deactivated_ += points;
  if (nodes + points > 0 && first_time_ < 0.0) first_time_ = c.t + c.dt;
}

template <int Dim>
void DeactivateOutside<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  auto put = [&](const std::string& key, const std::vector<Frozen>& frozen) {
    std::vector<std::int64_t> index;
    std::vector<double> x;
    for (const Frozen& f : frozen) {
      index.push_back(f.index);
      for (int d = 0; d < Dim; ++d) x.push_back(f.position[d]);
    }
    a.put(prefix + key + "_index", std::move(index));
    a.put(prefix + key + "_position", std::move(x));
  };
  put("nodes", nodes_);
  put("stress_points", stress_points_);
  a.put_integer(prefix + "stress_points_deactivated", stress_points_deactivated_);
  a.put_integer(prefix + "replacements_seen", replacements_seen_);
  a.put(prefix + "mass", mass_);
  a.put(prefix + "first_time", first_time_);
}

template <int Dim>
void DeactivateOutside<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  auto get = [&](const std::string& key, std::vector<Frozen>& frozen) {
    const auto& index = a.integers(prefix + key + "_index");
    const auto& x = a.doubles(prefix + key + "_position");
    frozen.clear();
    for (std::size_t k = 0; k < index.size(); ++k) {
      Vec<Dim> p;
      for (int d = 0; d < Dim; ++d) p[d] = x[k * Dim + static_cast<std::size_t>(d)];
      frozen.push_back({static_cast<Index>(index[k]), p});
    }
  };
  get("nodes", nodes_);
  get("stress_points", stress_points_);
  stress_points_deactivated_ = static_cast<long>(a.integer(prefix + "stress_points_deactivated"));
  replacements_seen_ = a.integer(prefix + "replacements_seen");
  mass_ = a.number(prefix + "mass");
  first_time_ = a.number(prefix + "first_time");
  mark_active(m_.nodes, active_nodes_, nodes_);
  mark_active(m_.stress_points, active_stress_points_, stress_points_);
}

template <int Dim>
void DeactivateOutside<Dim>::reordered(const Reordering& r) {
  const std::pair<const std::vector<Index>*, std::vector<Frozen>*> sets[] = {{&r.nodes, &nodes_},
                                                                              {&r.stress_points, &stress_points_}};
  for (const auto& [order, frozen] : sets) {
    if (order->empty()) continue;
    const std::vector<Index> new_index = inverse_order(*order);
    for (Frozen& f : *frozen) f.index = new_index[static_cast<std::size_t>(f.index)];
  }
}

template class DeactivateOutside<1>;
template class DeactivateOutside<2>;
template class DeactivateOutside<3>;

}  // namespace rktsph
