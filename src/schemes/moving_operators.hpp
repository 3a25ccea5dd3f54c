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

/// The interpolation weights of one operator's rows as a step evaluated them on the fly, kept
/// for the nodal filters, which apply P_EN and P_NE again after step 2 (method-notes eq.
/// (2.3.4)): row a's pairs lie in the slots [offsets[a], offsets[a] + count[a]) of its
/// candidates' CSR layout (a row keeps at most its candidates), so that the rows can be written
/// by any thread in any order. 12 bytes a candidate; filled only when a filter asks for it.
template <int Dim>
struct RecordedInterpolation {
  const Relation<Dim>* candidates = nullptr;
  std::vector<Index> count;   // pairs of each row
  std::vector<Index> source;  // the source of each slot
  std::vector<double> weight;

  /// Room for the rows of `c` (allocates only when the candidates outgrow every earlier step's).
  void prepare(const Relation<Dim>& c) {
    candidates = &c;
    count.resize(static_cast<std::size_t>(c.rows()));
    source.resize(c.indices().size());
    weight.resize(c.indices().size());
  }
  Index rows() const { return static_cast<Index>(count.size()); }
  /// The first slot of row a, after its `n` pairs are declared.
  std::size_t declare(Index a, std::size_t n) {
    count[static_cast<std::size_t>(a)] = static_cast<Index>(n);
    return static_cast<std::size_t>(candidates->offsets()[static_cast<std::size_t>(a)]);
  }
  std::size_t begin(Index a) const {
    return static_cast<std::size_t>(candidates->offsets()[static_cast<std::size_t>(a)]);
  }
  std::size_t end(Index a) const { return begin(a) + static_cast<std::size_t>(count[static_cast<std::size_t>(a)]); }
  std::size_t bytes() const {
    return count.capacity() * sizeof(Index) + source.capacity() * sizeof(Index) + weight.capacity() * sizeof(double);
  }
};

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
  /// On the fly with a nodal filter (the stress filter; V1's velocity filter): steps 1 and 2
  /// keep their rows' interpolation weights of t^n for the filter after step 2, which then
  /// applies the operators a stored step would (rebuilt at the start of the step).
  bool record_interpolation = false;
  RecordedInterpolation<Dim> nodes_to_stress_points;  // step 1's rows: P_EN
  RecordedInterpolation<Dim> stress_points_to_nodes;  // step 2's rows: P_NE

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
    return stress_point_position.capacity() * sizeof(Vec<Dim>) + stress_point_volume.capacity() * sizeof(double) +
           nodes_to_stress_points.bytes() + stress_points_to_nodes.bytes();
  }
};

}  // namespace rktsph
