#pragma once
// The stages V2 adds to V1's (method-notes §5.2): the neighbour relations and corrected
// operators rebuilt from the current positions at the start of every step.
#include <string_view>

#include "neighbours/relation.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

/// The corrected operators and the difference gradient recomputed from the particles' current
/// positions every step (never frozen), over Verlet lists: relations built with a skin around
/// the support, rebuilt only when some particle has moved half the skin since the last build
/// (so that no pair within the support can be missing). Operators are plain CSR: moved
/// particles no longer share row geometries.
template <int Dim>
class RebuildOperators final : public Stage {
 public:
  explicit RebuildOperators(StaggeredModel<Dim>& model);
  std::string_view name() const override { return "rebuild_operators"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return to_stress_points_.bytes() + to_nodes_.bytes() + constrained_.bytes();
  }

  /// Relations rebuilt (neighbour searches), operators recomputed, and the time of each, s.
  long relation_builds() const { return relation_builds_; }
  long operator_builds() const { return operator_builds_; }
  double relation_seconds() const { return relation_seconds_; }
  double operator_seconds() const { return operator_seconds_; }
  /// The skin of the Verlet lists, m.
  double skin() const { return skin_; }
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"neighbour_searches", static_cast<double>(relation_builds_)},
            {"neighbour_search_seconds", relation_seconds_},
            {"operator_builds", static_cast<double>(operator_builds_)},
            {"operator_build_seconds", operator_seconds_},
            {"verlet_skin", skin_}};
  }

 private:
  void build_relations();

  StaggeredModel<Dim>& m_;
  double skin_;
  Relation<Dim> to_stress_points_, to_nodes_, constrained_;
  std::vector<Vec<Dim>> constrained_positions_;
  std::vector<Vec<Dim>> nodes_at_build_, stress_points_at_build_;
  long relation_builds_ = 0, operator_builds_ = 0;
  double relation_seconds_ = 0.0, operator_seconds_ = 0.0;
};

}  // namespace rktsph
