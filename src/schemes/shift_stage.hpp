#pragma once
// V2's second regularisation (method-notes §5.2, "Regularisation"): the nodes pushed apart where
// they crowd (the inverse-square shifting of Xu et al. 2009), eqs. (5.2.5)-(5.2.7), with their
// fields carried to the new positions to first order. A shifted node is no longer a material point; its fields are
// those of the material now at its position. Off by default (solver.shift).
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "schemes/stage.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {

template <int Dim>
class ShiftNodes final : public Stage {
 public:
  /// After RebuildOperators (whose node relation it reads, and which it runs again after a
  /// shift) and ContactSelect (whose contact nodes move along their body only); before the
  /// free surface is detected on the shifted positions. Nodes whose support reaches the free
  /// surface of the last detection or a node held by a boundary entry stay.
  /// `corners`: the corner flags of the last detection (DetectFreeSurface::corners()), sized
  /// once the surface has been detected: no shift before that.
  ShiftNodes(StaggeredModel<Dim>& model, RebuildOperators<Dim>& rebuild, const RigidContact* contact,
             const std::vector<std::uint8_t>* corners);
  std::string_view name() const override { return "shift_nodes"; }
  void run(const StepContext& context) override;
  std::size_t scratch_bytes() const override {
    return (shift_.capacity() * sizeof(Vec<Dim>)) + increments_.capacity() * sizeof(double) + frozen_.capacity();
  }
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"shifts", static_cast<double>(shifts_)},
            {"shift_first_time", first_time_},
            {"shift_largest_over_dx", largest_ / m_.dx()},
            {"closest_pair_over_dx_last_check", closest_ / m_.dx()}};
  }
  long shifts() const { return shifts_; }
  /// The smallest distance between two nodes, over the node relation of the last build, m.
  double closest_pair() const;

 private:
  void shift(const StepContext& context);

  StaggeredModel<Dim>& m_;
  RebuildOperators<Dim>& rebuild_;
  const RigidContact* contact_ = nullptr;
  const std::vector<std::uint8_t>* corners_ = nullptr;
  Field<double, 1> flag_field_;
  std::vector<Vec<Dim>> shift_;
  std::vector<double> increments_;  // per node: the fields' first-order changes
  std::vector<std::uint8_t> frozen_;
  long shifts_ = 0;
  long steps_since_ = 0;
  double first_time_ = -1.0, largest_ = 0.0, closest_ = 0.0;
};

}  // namespace rktsph
