#pragma once
// V2: particles that leave the domain box are deactivated (method-notes §5.2, "Domain box";
// solver.domain_min / domain_max). A node or stress point found outside the box at the end of
// a step is frozen where it was found: its volume (and so its mass) set to zero, so that it
// takes no part in any other particle's sums, its velocity and stress to zero, and it is put
// back at that place after every later step. It stays in the sets (and in the VTU output,
// field `active` = 0) so that probes and checkpoints keep their meaning; its index follows
// any reordering of the sets. The count and
// the mass removed are reported (summary.json, particles.csv), so that the mass balance still
// closes: the particles' mass plus the deactivated mass is the initial mass.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
class DeactivateOutside final : public Stage {
 public:
  /// Throws InputError (naming solver.domain_min / domain_max) if a particle starts outside.
  explicit DeactivateOutside(StaggeredModel<Dim>& model);
  std::string_view name() const override { return "deactivate_outside"; }
  /// At the end of the step: the particles frozen before put back, the ones now outside frozen.
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return nodes_.capacity() * sizeof(Frozen) + stress_points_.capacity() * sizeof(Frozen);
  }
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  void reordered(const Reordering& reordering) override;
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"deactivated_nodes", static_cast<double>(nodes_.size())},
            {"deactivated_stress_points", static_cast<double>(stress_points_deactivated_)},
            {"deactivated_mass", mass_},
            {"first_deactivation_time", first_time_}};
  }
  /// Particles deactivated so far (nodes and stress points) and their mass, kg (2D: per unit
  /// thickness).
  long deactivated() const { return static_cast<long>(nodes_.size()) + stress_points_deactivated_; }
  double deactivated_mass() const { return mass_; }

 private:
  struct Frozen {
    Index index;
    Vec<Dim> position;
  };
  bool outside(const Vec<Dim>& x) const;
  /// Put the frozen particles of `set` back and freeze those now outside; returns how many.
  template <int NS>
  long sweep(ParticleSet<Dim>& set, Field<double, Dim> velocity, Field<double, NS> stress, Field<double, 1> active,
             std::vector<Frozen>& frozen);
  void mark_active(ParticleSet<Dim>& set, Field<double, 1> active, const std::vector<Frozen>& frozen);

  StaggeredModel<Dim>& m_;
  Vec<Dim> lo_, hi_;
  Field<double, 1> active_nodes_, active_stress_points_;
  std::vector<Frozen> nodes_, stress_points_;
  long stress_points_deactivated_ = 0;  // all so far (a re-seeding drops the frozen ones)
  std::int64_t replacements_seen_ = 0;
  double mass_ = 0.0;
  double first_time_ = -1.0;
};

}  // namespace rktsph
