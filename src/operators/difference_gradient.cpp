// The difference form of the corrected gradient at chosen targets (method-notes §3.2, fix (a)
// of §0.3): rows of weights c_b with grad f(x_a) = sum_b c_b (f_b - f_a), built for the
// constrained nodes (V1, V2) and the detected surface nodes (V2).
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "core/error.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/row_pairs.hpp"

namespace rktsph {

using detail::Pair;
using detail::row_pairs;

template <int Dim>
RelationOptions difference_gradient_relation_options(const CubicSplineKernel<Dim>& kernel) {
  return {kernel.support_radius(), 1, true};
}

namespace {

// Append the difference-gradient row of target a (row a of the relation) to g.
template <int Dim>
void append_difference_row(const Relation<Dim>& relation, Index a, const Vec<Dim>& target,
                           const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                           std::vector<Pair<Dim>>& pairs, DifferenceGradient<Dim>& g) {
  // A wider relation (a Verlet list with a skin) is cut back to the support.
  const bool filter = relation.options().radius > kernel.support_radius();
  const double r2 = kernel.support_radius() * kernel.support_radius();
  {
    row_pairs(relation, a, target, sources, pairs);
    if (filter) std::erase_if(pairs, [&](const Pair<Dim>& p) { return p.x_ab.squaredNorm() >= r2; });
    Mat<Dim> A = Mat<Dim>::Zero();
    for (const auto& p : pairs) {
      const double V = sources.volume[static_cast<std::size_t>(p.b)];
      A += V * kernel.gradient(p.x_ab) * (-p.x_ab).transpose();
    }
    // method-notes §3.2: A_a = sum V_b grad_a W_ab (x) (x_b - x_a); fall back to the identity
    // when it is singular. A is O(1) for a reasonable support; a tiny determinant means too few
    // sources.
    const bool ok = std::abs(A.determinant()) > 1e-8;
    const Mat<Dim> Ainv = ok ? Mat<Dim>(A.inverse()) : Mat<Dim>::Identity();
    Vec<Dim> sum = Vec<Dim>::Zero();
    for (const auto& p : pairs) {
      const double V = sources.volume[static_cast<std::size_t>(p.b)];
      const Vec<Dim> gw = V * kernel.gradient(p.x_ab);
      const Vec<Dim> c = Ainv * gw;
      g.source.push_back(p.b);
      g.weight.push_back(c);
      sum += c;
    }
    g.weight_sum.push_back(sum);
    g.row_start.push_back(static_cast<Index>(g.source.size()));
  }
}

// The pair scratch of the row builders, kept per thread: rebuilt every V2 step, it allocates
// only until it has grown to the largest row.
template <int Dim>
std::vector<Pair<Dim>>& pair_scratch() {
  thread_local std::vector<Pair<Dim>> pairs;
  return pairs;
}

template <int Dim>
void clear_gradient(DifferenceGradient<Dim>& g) {
  g.row_start.assign(1, 0);
  g.source.clear();
  g.weight.clear();
  g.weight_sum.clear();
}

}  // namespace

template <int Dim>
void build_difference_gradient_into(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                    const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                    DifferenceGradient<Dim>& out) {
  if (relation.rows() != static_cast<Index>(targets.size()) || !relation.options().sorted) {
    throw SolverError("difference gradient: the relation must have one sorted row per target");
  }
  clear_gradient(out);
  std::vector<Pair<Dim>>& pairs = pair_scratch<Dim>();
  for (Index a = 0; a < relation.rows(); ++a) {
    append_difference_row(relation, a, targets[static_cast<std::size_t>(a)], sources, kernel, pairs, out);
  }
}

template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel) {
  DifferenceGradient<Dim> g;
  build_difference_gradient_into(relation, targets, sources, kernel, g);
  return g;
}

template <int Dim>
void build_difference_gradient_rows(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                    const std::vector<Index>& which, const ParticleSet<Dim>& sources,
                                    const CubicSplineKernel<Dim>& kernel, DifferenceGradient<Dim>& out) {
  if (relation.rows() != static_cast<Index>(targets.size()) || !relation.options().sorted) {
    throw SolverError("difference gradient: the relation must have one sorted row per target");
  }
  clear_gradient(out);
  std::vector<Pair<Dim>>& pairs = pair_scratch<Dim>();
  for (const Index a : which) {
    append_difference_row(relation, a, targets[static_cast<std::size_t>(a)], sources, kernel, pairs, out);
  }
}

template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const std::vector<Vec<Dim>>& targets, const std::vector<Index>& which,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel) {
  std::vector<Vec<Dim>> selected;
  for (Index a : which) selected.push_back(targets[static_cast<std::size_t>(a)]);
  Relation<Dim> relation;
  relation.build(selected, sources.position, difference_gradient_relation_options(kernel));
  return build_difference_gradient(relation, selected, sources, kernel);
}

#define RKTSPH_INSTANTIATE(D)                                                                                        \
  template RelationOptions difference_gradient_relation_options<D>(const CubicSplineKernel<D>&);                     \
  template void build_difference_gradient_into<D>(const Relation<D>&, const std::vector<Vec<D>>&,                    \
                                                  const ParticleSet<D>&, const CubicSplineKernel<D>&,                \
                                                  DifferenceGradient<D>&);                                           \
  template void build_difference_gradient_rows<D>(const Relation<D>&, const std::vector<Vec<D>>&,                    \
                                                  const std::vector<Index>&, const ParticleSet<D>&,                  \
                                                  const CubicSplineKernel<D>&, DifferenceGradient<D>&);              \
  template DifferenceGradient<D> build_difference_gradient<D>(const Relation<D>&, const std::vector<Vec<D>>&,        \
                                                              const ParticleSet<D>&, const CubicSplineKernel<D>&);   \
  template DifferenceGradient<D> build_difference_gradient<D>(const std::vector<Vec<D>>&, const std::vector<Index>&, \
                                                              const ParticleSet<D>&, const CubicSplineKernel<D>&);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
