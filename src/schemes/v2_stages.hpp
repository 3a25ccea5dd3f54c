#pragma once
// The stages V2 adds to V1's (method-notes §5.2): the neighbour relations and corrected
// operators rebuilt from the current positions at the start of every step.
#include <string_view>

#include "neighbours/relation.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

/// Rebuild both cross-set relations (and that of the constrained nodes), then the corrected
/// operators and the difference gradient, from the particles' current positions. Operators
/// are not compressed into shared patterns: moved particles no longer share geometries.
template <int Dim>
class RebuildOperators final : public Stage {
 public:
  explicit RebuildOperators(StaggeredModel<Dim>& model);
  std::string_view name() const override { return "rebuild_operators"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return to_stress_points_.bytes() + to_nodes_.bytes() + constrained_.bytes();
  }

  long rebuilds() const { return rebuilds_; }
  double seconds() const { return seconds_; }

 private:
  StaggeredModel<Dim>& m_;
  Relation<Dim> to_stress_points_, to_nodes_, constrained_;
  std::vector<Vec<Dim>> constrained_positions_;
  long rebuilds_ = 0;
  double seconds_ = 0.0;
};

}  // namespace rktsph
