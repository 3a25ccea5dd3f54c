#include "operators/corrected_operator.hpp"

#include <algorithm>
#include <numeric>

#include <Eigen/Dense>

#include "neighbours/cell_list.hpp"

namespace rktsph {

namespace {

template <int Dim>
struct Pair {
  Index b;
  Vec<Dim> x_ab;  // x_a - x_b
  double r;
};

template <int Dim>
std::vector<Pair<Dim>> sorted_neighbours(const CellList<Dim>& cells, const Vec<Dim>& x) {
  std::vector<Pair<Dim>> pairs;
  cells.for_each_neighbour(x, [&](Index b, const Vec<Dim>& x_ab, double r) {
    pairs.push_back({b, x_ab, r});
  });
  std::sort(pairs.begin(), pairs.end(), [](const auto& p, const auto& q) { return p.b < q.b; });
  return pairs;
}

}  // namespace

template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources,
                                                const CubicSplineKernel<Dim>& kernel) {
  constexpr int N = Dim + 1;
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  const double h = kernel.h();
  const CellList<Dim> cells(sources.position, kernel.support_radius());
  const auto nt = static_cast<Index>(targets.size());

  CorrectedOperator<Dim> op;
  // Pass 1: count the sources of every target, so that rows can be filled in parallel.
  op.row_start.assign(static_cast<std::size_t>(nt) + 1, 0);
#pragma omp parallel for schedule(static) if (nt > 2048)
  for (Index a = 0; a < nt; ++a) {
    Index count = 0;
    cells.for_each_neighbour(targets[static_cast<std::size_t>(a)], [&](Index, const Vec<Dim>&, double) { ++count; });
    op.row_start[static_cast<std::size_t>(a) + 1] = count;
  }
  for (std::size_t a = 0; a < static_cast<std::size_t>(nt); ++a) op.row_start[a + 1] += op.row_start[a];
  const auto npairs = static_cast<std::size_t>(op.row_start.back());
  op.source.resize(npairs);
  op.interp.resize(npairs);
  op.grad.resize(npairs);

  Index degenerate = 0;
  // Pass 2: per target, the sorted pairs and the weights M_a^{-1} V_b [W_ab; h grad_a W_ab].
#pragma omp parallel reduction(+ : degenerate) if (nt > 2048)
  {
    std::vector<Pair<Dim>> pairs;
    std::vector<VecN> basis;
#pragma omp for schedule(static)
    for (Index a = 0; a < nt; ++a) {
      pairs.clear();
      cells.for_each_neighbour(targets[static_cast<std::size_t>(a)], [&](Index b, const Vec<Dim>& x_ab, double r) {
        pairs.push_back({b, x_ab, r});
      });
      std::sort(pairs.begin(), pairs.end(), [](const auto& p, const auto& q) { return p.b < q.b; });
      // Work in units of h so that the (n_d+1) system is well scaled.
      MatN M = MatN::Zero();
      basis.resize(pairs.size());
      double shepard = 0.0;
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto& p = pairs[k];
        const double V = sources.volume[static_cast<std::size_t>(p.b)];
        VecN w;
        w[0] = V * kernel.value(p.r);
        w.template tail<Dim>() = V * h * kernel.gradient(p.x_ab);
        VecN dx;
        dx[0] = 1.0;
        dx.template tail<Dim>() = -p.x_ab / h;  // (x_b - x_a)/h
        M += w * dx.transpose();
        basis[k] = w;
        shepard += w[0];
      }
      // M is O(1) in these units; a tiny determinant means too few or collinear sources.
      const bool ok = !pairs.empty() && std::abs(M.determinant()) > 1e-8;
      MatN Minv = MatN::Identity();
      if (ok) Minv = M.inverse();
      else ++degenerate;
      auto k0 = static_cast<std::size_t>(op.row_start[static_cast<std::size_t>(a)]);
      for (std::size_t k = 0; k < pairs.size(); ++k, ++k0) {
        VecN c;
        if (ok) {
          c = Minv * basis[k];
        } else {
          // Too few sources for the corrected system: Shepard interpolation and the plain
          // kernel gradient (METHOD.md §3.2 guard).
          c = basis[k];
          c[0] = shepard > 0.0 ? basis[k][0] / shepard : 0.0;
        }
        op.source[k0] = pairs[k].b;
        op.interp[k0] = c[0];
        for (int d = 0; d < Dim; ++d) op.grad[k0][static_cast<std::size_t>(d)] = c[d + 1] / h;
      }
    }
  }
  op.degenerate_rows = degenerate;
  return op;
}

template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const std::vector<Vec<Dim>>& targets,
                                                  const std::vector<Index>& which,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel) {
  const CellList<Dim> cells(sources.position, kernel.support_radius());
  DifferenceGradient<Dim> g;
  g.row_start.push_back(0);
  for (Index a : which) {
    const Vec<Dim>& xa = targets[static_cast<std::size_t>(a)];
    const auto pairs = sorted_neighbours(cells, xa);
    Mat<Dim> A = Mat<Dim>::Zero();
    for (const auto& p : pairs) {
      const double V = sources.volume[static_cast<std::size_t>(p.b)];
      A += V * kernel.gradient(p.x_ab) * (-p.x_ab).transpose();
    }
    // METHOD.md §3.2: A_a = sum V_b grad_a W_ab (x) (x_b - x_a); fall back to the identity when
    // it is singular.
    // A is O(1) for a reasonable support; a tiny determinant means too few sources.
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
  return g;
}

#define RKTSPH_INSTANTIATE(D)                                                                   \
  template CorrectedOperator<D> build_corrected_operator<D>(                                    \
      const std::vector<Vec<D>>&, const ParticleSet<D>&, const CubicSplineKernel<D>&);          \
  template DifferenceGradient<D> build_difference_gradient<D>(                                  \
      const std::vector<Vec<D>>&, const std::vector<Index>&, const ParticleSet<D>&,            \
      const CubicSplineKernel<D>&);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
