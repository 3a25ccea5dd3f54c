// Saving and restoring the state of a Simulation for checkpoints (io/checkpoint.hpp): what
// Simulation::step carries from one step to the next, so that a resumed run continues bit for
// bit as if it had not stopped.
#include <algorithm>
#include <cstring>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {

namespace {

template <int Dim>
void save_set(const ParticleSet<Dim>& set, std::uint64_t made, io::StateArchive& a) {
  const std::string p = set.name() + "/";
  a.put_integer(p + "made_from_case", static_cast<std::int64_t>(made));
  std::vector<double> x;
  x.reserve(set.position.size() * Dim);
  for (const auto& v : set.position) {
    for (int d = 0; d < Dim; ++d) x.push_back(v[d]);
  }
  a.put(p + "position", std::move(x));
  a.put(p + "volume", set.volume);
  a.put(p + "density", set.density);
  a.put(p + "material", std::vector<std::int64_t>(set.material.begin(), set.material.end()));
  a.put(p + "global_id", set.global_id);
  a.put_integer(p + "replacements", set.replacements());
  const auto infos = set.fields();
  for (std::size_t id = 0; id < infos.size(); ++id) {
    const FieldInfo& f = infos[id];
    if ((f.flags & kFieldEvolving) == 0) continue;
    const std::string key = p + "fields/" + f.name;
    const int i = static_cast<int>(id);
    switch (f.type) {
      case FieldType::f64: {
        const auto v = set.template values<double>(i);
        a.put(key, std::vector<double>(v.begin(), v.end()));
        break;
      }
      case FieldType::i64: {
        const auto v = set.template values<std::int64_t>(i);
        a.put(key, std::vector<std::int64_t>(v.begin(), v.end()));
        break;
      }
      case FieldType::u8: {
        const auto v = set.template values<std::uint8_t>(i);
        a.put(key, std::vector<std::uint8_t>(v.begin(), v.end()));
        break;
      }
    }
  }
}

template <class T>
void copy_into(std::span<T> to, const std::vector<T>& from, const std::string& key) {
  if (from.size() != to.size()) {
    throw InputError(
        fmt::format("the checkpoint's '{}' has {} values, this case {}: the case changed since it was written", key,
                    from.size(), to.size()));
  }
  std::copy(from.begin(), from.end(), to.begin());
}

template <int Dim>
void load_set(ParticleSet<Dim>& set, std::uint64_t made, const io::StateArchive& a) {
  const std::string p = set.name() + "/";
  // The particles are made again from the case; as made they must be the checkpoint's, bit for
  // bit (a fingerprint, since in large deformation they have moved since).
  const auto& x = a.doubles(p + "position");
  if (a.has(p + "replacements") && a.integer(p + "replacements") > 0 &&
      static_cast<std::uint64_t>(a.integer(p + "made_from_case")) == made) {
    // The set was renewed during the run (stress points re-seeded, particles/reseed.hpp): made
    // from the case it is not the checkpoint's; take the checkpoint's particles.
    const auto& ids = a.integers(p + "global_id");
    const auto& mats = a.integers(p + "material");
    const std::size_t n = ids.size();
    if (x.size() != n * Dim || mats.size() != n || a.doubles(p + "volume").size() != n ||
        a.doubles(p + "density").size() != n) {
      throw InputError(
          fmt::format("the checkpoint's {} are inconsistent (renewed set of {} particles)", set.name(), n));
    }
    std::vector<Vec<Dim>> positions(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < Dim; ++d) positions[i][d] = x[i * Dim + static_cast<std::size_t>(d)];
    }
    set.replace(std::move(positions), a.doubles(p + "volume"), a.doubles(p + "density"),
                std::vector<int>(mats.begin(), mats.end()), ids, a.integer(p + "replacements"));
  }
  const bool same = x.size() == set.position.size() * Dim && a.integers(p + "global_id") == set.global_id &&
                    static_cast<std::uint64_t>(a.integer(p + "made_from_case")) == made;
  if (!same) {
    throw InputError(
        fmt::format("the checkpoint's {} are not this case's ({} in the checkpoint, {} here): the case "
                    "changed since it was written",
                    set.name(), x.size() / Dim, set.position.size()));
  }
  for (std::size_t i = 0; i < set.position.size(); ++i) {
    for (int d = 0; d < Dim; ++d) set.position[i][d] = x[i * Dim + static_cast<std::size_t>(d)];
  }
  copy_into(std::span<double>(set.volume), a.doubles(p + "volume"), p + "volume");
  copy_into(std::span<double>(set.density), a.doubles(p + "density"), p + "density");
  const auto infos = set.fields();
  for (std::size_t id = 0; id < infos.size(); ++id) {
    const FieldInfo& f = infos[id];
    if ((f.flags & kFieldEvolving) == 0) continue;
    const std::string key = p + "fields/" + f.name;
    const int i = static_cast<int>(id);
    switch (f.type) {
      case FieldType::f64:
        copy_into(set.template values<double>(i), a.doubles(key), key);
        break;
      case FieldType::i64:
        copy_into(set.template values<std::int64_t>(i), a.integers(key), key);
        break;
      case FieldType::u8:
        copy_into(set.template values<std::uint8_t>(i), a.bytes(key), key);
        break;
    }
  }
}

// The order that takes the set as made to the checkpoint's order (V2 sorts its particles by
// cell as they move): order[k] is the made particle whose global id the checkpoint has at k.
// Empty when the orders agree, when the set is renewed from the checkpoint (re-seeded stress
// points are taken as they are) or when the ids are no permutation of the made ones (then
// load_set names the mismatch).
template <int Dim>
std::vector<Index> checkpoint_order(const ParticleSet<Dim>& set, const io::StateArchive& a) {
  const std::string p = set.name() + "/";
  if (a.has(p + "replacements") && a.integer(p + "replacements") > 0) return {};
  const auto& ids = a.integers(p + "global_id");
  if (ids.size() != set.global_id.size() || ids == set.global_id) return {};
  std::vector<std::pair<std::int64_t, Index>> made(set.global_id.size());
  for (std::size_t i = 0; i < made.size(); ++i) made[i] = {set.global_id[i], static_cast<Index>(i)};
  std::sort(made.begin(), made.end());
  std::vector<Index> order(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto it = std::lower_bound(made.begin(), made.end(), std::make_pair(ids[k], Index{0}));
    if (it == made.end() || it->first != ids[k]) return {};
    order[k] = it->second;
  }
  return order;
}

std::string stage_prefix(std::size_t index, std::string_view name) {
  return fmt::format("stages/{:02d}_{}/", index, name);
}

}  // namespace

template <int Dim>
void Simulation<Dim>::save_state(io::StateArchive& a) const {
  a.put_text("scheme/name", scheme_->name());
  a.put_integer("scheme/dimension", Dim);
  save_set(model_->nodes, nodes_made_, a);
  save_set(model_->stress_points, stress_points_made_, a);
  clock_.save(a);
  for (std::size_t k = 0; k < scheme_->stages().size(); ++k) {
    const Stage& s = *scheme_->stages()[k];
    s.save(a, stage_prefix(k, s.name()));
  }
}

template <int Dim>
void Simulation<Dim>::load_state(const io::StateArchive& a) {
  if (a.text("scheme/name") != scheme_->name() || a.integer("scheme/dimension") != Dim) {
    throw InputError(fmt::format("the checkpoint is of the {}D scheme '{}', this case runs the {}D scheme '{}'",
                                 a.integer("scheme/dimension"), a.text("scheme/name"), Dim, scheme_->name()));
  }
  // The particles as made, put in the checkpoint's order first (with every table that holds
  // their indices), then given its values.
  Reordering order{checkpoint_order(model_->nodes, a), checkpoint_order(model_->stress_points, a)};
  if (!order.empty()) reorder(order);
  load_set(model_->nodes, nodes_made_, a);
  load_set(model_->stress_points, stress_points_made_, a);
  clock_.load(a);
  for (std::size_t k = 0; k < scheme_->stages().size(); ++k) {
    Stage& s = *scheme_->stages()[k];
    s.load(a, stage_prefix(k, s.name()));
  }
}

template void Simulation<1>::save_state(io::StateArchive&) const;
template void Simulation<2>::save_state(io::StateArchive&) const;
template void Simulation<3>::save_state(io::StateArchive&) const;
template void Simulation<1>::load_state(const io::StateArchive&);
template void Simulation<2>::load_state(const io::StateArchive&);
template void Simulation<3>::load_state(const io::StateArchive&);

}  // namespace rktsph
