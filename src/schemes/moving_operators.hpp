#pragma once
// What V2's steps need to apply their corrected operators on the fly (method-notes §5.2,
// "Operators on the fly"), and the record of the operators' degenerate and regularised rows in
// either storage.
// RebuildOperators (schemes/v2_stages.hpp) owns it and keeps the candidate relations current;
// step 1 saves the stress points' positions and volumes at t^n here before it moves them, so
// that step 2's operator is built on the geometry of t^n, as a stored operator rebuilt at the
// start of the step is.
#include <algorithm>
#include <vector>

#include "core/types.hpp"
#include "neighbours/relation.hpp"

namespace rktsph {

template <int Dim>
struct MovingOperators {
  /// true: the steps evaluate each row from the candidates (CorrectedRow::apply); false: the
  /// weights are stored by RebuildOperators in the model's operators.
  bool on_the_fly = true;
  /// The Verlet candidates (support plus skin) of step 1's rows (nodes near each stress point)
  /// and of step 2's rows (stress points near each node); the rows keep those within r2.
  const Relation<Dim>* nodes_near_stress_points = nullptr;
  const Relation<Dim>* stress_points_near_nodes = nullptr;
  double r2 = 0.0;  // m^2: the support less the relative gap of operator_relation_options
  /// The stress points at t^n, written by step 1, read by step 2.
  std::vector<Vec<Dim>> stress_point_position;
  std::vector<double> stress_point_volume;

  /// The most rows of the two operators with too few neighbours (plain SPH sums there) at any
  /// step, and the time they first appeared (-1: never). A body tearing apart shows here.
  Index degenerate_max = 0;
  double degenerate_first_time = -1.0;
  /// The same for the rows the gradient floor regularised (method-notes eq. (3.2.6)): a thin
  /// sheet or a lone particle.
  Index regularised_max = 0;
  double regularised_first_time = -1.0;
  void note_rows(Index degenerate, Index regularised, double t) {
    if (degenerate > 0 && degenerate_first_time < 0.0) degenerate_first_time = t;
    degenerate_max = std::max(degenerate_max, degenerate);
    if (regularised > 0 && regularised_first_time < 0.0) regularised_first_time = t;
    regularised_max = std::max(regularised_max, regularised);
  }

  /// Room for the stress points of a step (allocates only when re-seeding made more than ever).
  void resize(Index stress_points) {
    stress_point_position.resize(static_cast<std::size_t>(stress_points));
    stress_point_volume.resize(static_cast<std::size_t>(stress_points));
  }
  std::size_t bytes() const {
    return stress_point_position.capacity() * sizeof(Vec<Dim>) + stress_point_volume.capacity() * sizeof(double);
  }
};

}  // namespace rktsph
