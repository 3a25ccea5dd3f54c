#include "operators/laplacian.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "core/error.hpp"
#include "neighbours/cell_list.hpp"

namespace rktsph {

template <int Dim>
RelationOptions laplacian_relation_options(const CubicSplineKernel<Dim>& kernel) {
  // Rows in the cell list's visiting order (the order the sums below are formed in).
  return {kernel.support_radius(), 1, false};
}

namespace {

// The rows of L and S, emitted one at a time in row order (no triplet list, no per-pair store
// for the whole set: the pressure set-up's peak memory). Pass 1 forms c_I and the gradient
// correction of every node from its pairs; pass 2 gathers each row's pairs again and emits its
// entries, columns increasing, duplicates (a neighbour and its mirror image) summed, the
// diagonal (zero row sum) added last. emit(i, columns, full, symmetric).
template <int Dim, class Emit>
Index laplacian_rows(const Relation<Dim>& relation, const ParticleSet<Dim>& nodes, const CubicSplineKernel<Dim>& kernel,
                     const std::vector<std::uint8_t>& wall_axes, const std::vector<MirrorPlane>& mirrors,
                     const std::vector<std::uint8_t>& mirror_mask, std::vector<double>& c, Emit&& emit) {
  const auto n = static_cast<std::size_t>(nodes.size());
  if (relation.rows() != nodes.size() || relation.options().sorted ||
      relation.options().radius != kernel.support_radius()) {
    throw SolverError("node Laplacian: the relation must be built with laplacian_relation_options");
  }
  // Mirror images are searched around the image points (not particles), with a cell list.
  std::optional<CellList<Dim>> cells;
  if (!mirrors.empty()) cells.emplace(nodes.position, kernel.support_radius());

  struct Pair {
    Index j;
    Vec<Dim> x_ij;  // x_I - x_J
    double r;
  };
  std::vector<Pair> pairs;
  auto gather = [&](std::size_t i) {
    pairs.clear();
    const Vec<Dim>& xi = nodes.position[i];
    for (const Index j : relation.row(static_cast<Index>(i))) {
      const Vec<Dim> x_ij = xi - nodes.position[static_cast<std::size_t>(j)];
      const double r = std::sqrt(x_ij.squaredNorm());
      if (static_cast<std::size_t>(j) != i && r > 0.0) pairs.push_back({j, x_ij, r});
    }
    // Mirror images across the impermeable walls within reach (even extension, p_J' = p_J).
    for (std::size_t k = 0; k < mirrors.size() && k < 8; ++k) {
      if (!mirror_mask.empty() && ((mirror_mask[i] >> k) & 1u) == 0) continue;
      const MirrorPlane& m = mirrors[k];
      const double dist = (m.coord - xi[m.axis]) * m.outward;  // >= 0 inside the body
      if (dist < -1e-9 * kernel.h() || dist >= kernel.support_radius()) continue;
      Vec<Dim> image = xi;  // the sources near the image of I are the images of I's partners
      image[m.axis] = 2.0 * m.coord - xi[m.axis];
      cells->for_each_neighbour(image, [&](Index j, const Vec<Dim>&, double) {
        Vec<Dim> xj = nodes.position[static_cast<std::size_t>(j)];
        if ((m.coord - xj[m.axis]) * m.outward < -1e-9 * kernel.h()) return;  // not in this body half
        xj[m.axis] = 2.0 * m.coord - xj[m.axis];
        const Vec<Dim> x_ij = xi - xj;
        const double r = x_ij.norm();
        if (r > 1e-12 * kernel.h() && r < kernel.support_radius()) pairs.push_back({j, x_ij, r});
      });
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.j < b.j; });
  };

  Index degenerate = 0;
  c.assign(n, 2.0);
  // Per node: the vector b_I = c_I A_I^{-T} P g_I that multiplies V_J grad_I W_IJ in the
  // gradient correction (zero where A_I is singular).
  std::vector<Vec<Dim>> corr(n, Vec<Dim>::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    gather(i);
    Mat<Dim> A = Mat<Dim>::Zero();
    Vec<Dim> g = Vec<Dim>::Zero();
    for (const Pair& p : pairs) {
      const double V = nodes.volume[static_cast<std::size_t>(p.j)];
      const Vec<Dim> gw = V * kernel.gradient(p.x_ij);
      A -= gw * p.x_ij.transpose();  // grad_I W_IJ (x) (x_J - x_I)
      g += gw;
    }
    // Singularity guard (method-notes §3.5): A is dimensionless, about the identity inside, about
    // 1/2 along the normal at a wall; a small determinant relative to the trace means too few
    // neighbours on one side (c_I = 2, no gradient correction).
    const double det = A.determinant();
    const double scale = std::pow(std::abs(A.trace()) / Dim, Dim);
    if (pairs.size() < static_cast<std::size_t>(Dim) + 1 || !(det > 1e-3 * scale) || scale == 0.0) {
      ++degenerate;
      continue;
    }
    const Mat<Dim> Ainv = A.inverse();
    c[i] = 2.0 / Dim * Ainv.trace();
    Vec<Dim> Pg = g;
    if (!wall_axes.empty()) {
      for (int d = 0; d < Dim; ++d) {
        if ((wall_axes[i] >> d) & 1u) Pg[d] = 0.0;  // prescribed (zero) normal derivative
      }
    }
    corr[i] = c[i] * Ainv.transpose() * Pg;
  }

  std::vector<Index> columns;
  std::vector<double> full, sym;
  for (std::size_t i = 0; i < n; ++i) {
    gather(i);
    columns.clear();
    full.clear();
    sym.clear();
    double diag_full = 0.0, diag_sym = 0.0;
    const double Vi = nodes.volume[i];
    std::size_t diag_at = std::size_t(-1);
    auto entry = [&](Index j, double lf, double ls) {
      if (!columns.empty() && columns.back() == j) {
        full.back() += lf;
        sym.back() += ls;
      } else {
        if (j > static_cast<Index>(i) && diag_at == std::size_t(-1)) {  // the diagonal's place
          diag_at = columns.size();
          columns.push_back(static_cast<Index>(i));
          full.push_back(0.0);
          sym.push_back(0.0);
        }
        if (j == static_cast<Index>(i)) diag_at = columns.size();
        columns.push_back(j);
        full.push_back(lf);
        sym.push_back(ls);
      }
    };
    for (const Pair& p : pairs) {
      const auto j = static_cast<std::size_t>(p.j);
      const double Vj = nodes.volume[j];
      const double F = kernel.derivative(p.r) / p.r;  // < 0 inside the support
      const double lf = c[i] * Vj * (-F) - corr[i].dot(Vj * kernel.gradient(p.x_ij));
      const double ls = 0.25 * (c[i] + c[j]) * (Vi + Vj) * (-F);
      entry(p.j, lf, ls);
      diag_full -= lf;
      diag_sym -= ls;
    }
    if (diag_at == std::size_t(-1)) {
      diag_at = columns.size();
      columns.push_back(static_cast<Index>(i));
      full.push_back(0.0);
      sym.push_back(0.0);
    }
    full[diag_at] += diag_full;
    sym[diag_at] += diag_sym;
    emit(i, std::span<const Index>(columns), std::span<const double>(full), std::span<const double>(sym));
  }
  return degenerate;
}

}  // namespace

template <int Dim>
NodeLaplacian<Dim> build_node_laplacian(const Relation<Dim>& relation, const ParticleSet<Dim>& nodes,
                                        const CubicSplineKernel<Dim>& kernel,
                                        const std::vector<std::uint8_t>& wall_axes,
                                        const std::vector<MirrorPlane>& mirrors,
                                        const std::vector<std::uint8_t>& mirror_mask) {
  const auto n = static_cast<Eigen::Index>(nodes.size());
  NodeLaplacian<Dim> out;
  out.full.resize(n, n);
  out.symmetric.resize(n, n);
  // CSR filled row by row (Eigen's low-level insertBack API, no triplets).
  const auto guess = static_cast<Eigen::Index>(relation.pairs() + nodes.size());
  out.full.reserve(guess);
  out.symmetric.reserve(guess);
  out.degenerate_rows = laplacian_rows<Dim>(
      relation, nodes, kernel, wall_axes, mirrors, mirror_mask, out.c,
      [&](std::size_t i, std::span<const Index> cols, std::span<const double> full, std::span<const double> sym) {
        const auto r = static_cast<Eigen::Index>(i);
        out.full.startVec(r);
        out.symmetric.startVec(r);
        for (std::size_t k = 0; k < cols.size(); ++k) {
          out.full.insertBack(r, cols[k]) = full[k];
          out.symmetric.insertBack(r, cols[k]) = sym[k];
        }
      });
  out.full.finalize();
  out.symmetric.finalize();
  return out;
}

template <int Dim>
NodeLaplacianPatterns build_node_laplacian_patterns(const Relation<Dim>& relation, const ParticleSet<Dim>& nodes,
                                                    const CubicSplineKernel<Dim>& kernel,
                                                    const std::vector<MirrorPlane>& mirrors,
                                                    const std::vector<std::uint8_t>& mirror_mask, bool with_full) {
  const Index n = nodes.size();
  PatternMatrix::Builder full(with_full ? n : 0, n), sym(n, n);
  NodeLaplacianPatterns out;
  out.degenerate_rows = laplacian_rows<Dim>(
      relation, nodes, kernel, {}, mirrors, mirror_mask, out.c,
      [&](std::size_t, std::span<const Index> cols, std::span<const double> f, std::span<const double> s) {
        if (with_full) full.add_row(cols, f);
        sym.add_row(cols, s);
      });
  out.full = full.finish();
  out.symmetric = sym.finish();
  return out;
}

template <int Dim>
NodeLaplacian<Dim> build_node_laplacian(const ParticleSet<Dim>& nodes, const CubicSplineKernel<Dim>& kernel,
                                        const std::vector<std::uint8_t>& wall_axes,
                                        const std::vector<MirrorPlane>& mirrors,
                                        const std::vector<std::uint8_t>& mirror_mask) {
  Relation<Dim> relation;
  relation.build(nodes.position, nodes.position, laplacian_relation_options(kernel));
  return build_node_laplacian(relation, nodes, kernel, wall_axes, mirrors, mirror_mask);
}

#define RKTSPH_INSTANTIATE(D)                                                                                          \
  template RelationOptions laplacian_relation_options<D>(const CubicSplineKernel<D>&);                                 \
  template NodeLaplacian<D> build_node_laplacian<D>(                                                                   \
      const Relation<D>&, const ParticleSet<D>&, const CubicSplineKernel<D>&, const std::vector<std::uint8_t>&,        \
      const std::vector<MirrorPlane>&, const std::vector<std::uint8_t>&);                                              \
  template NodeLaplacianPatterns build_node_laplacian_patterns<D>(                                                     \
      const Relation<D>&, const ParticleSet<D>&, const CubicSplineKernel<D>&, const std::vector<MirrorPlane>&,          \
      const std::vector<std::uint8_t>&, bool);                                                                         \
  template NodeLaplacian<D> build_node_laplacian<D>(const ParticleSet<D>&, const CubicSplineKernel<D>&,                \
                                                    const std::vector<std::uint8_t>&, const std::vector<MirrorPlane>&, \
                                                    const std::vector<std::uint8_t>&);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

template <int Dim>
Eigen::SparseMatrix<double, Eigen::RowMajor> build_filter_gradient_part(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& symmetric, const std::vector<Vec<Dim>>& position,
    const std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, Dim>& gradient) {
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  using Triplet = Eigen::Triplet<double>;
  const auto n = symmetric.rows();
  // T_d: (T_d g)_I = sum_J S_IJ 1/2 (g_I + g_J) (x_J - x_I)_d.
  Sparse out(n, n);
  for (int d = 0; d < Dim; ++d) {
    std::vector<Triplet> t;
    for (Eigen::Index i = 0; i < n; ++i) {
      double diag = 0.0;
      for (Sparse::InnerIterator it(symmetric, i); it; ++it) {
        if (it.col() == i) continue;
        const double w = 0.5 * it.value() *
                         (position[static_cast<std::size_t>(it.col())][d] - position[static_cast<std::size_t>(i)][d]);
        t.emplace_back(i, it.col(), w);
        diag += w;
      }
      t.emplace_back(i, i, diag);
    }
    Sparse T(n, n);
    T.setFromTriplets(t.begin(), t.end());
    out += Sparse(T * gradient[static_cast<std::size_t>(d)]);
  }
  out.prune(0.0, 1e-14);
  return out;
}

template Eigen::SparseMatrix<double, Eigen::RowMajor> build_filter_gradient_part<1>(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>&, const std::vector<Vec<1>>&,
    const std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 1>&);
template Eigen::SparseMatrix<double, Eigen::RowMajor> build_filter_gradient_part<2>(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>&, const std::vector<Vec<2>>&,
    const std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 2>&);
template Eigen::SparseMatrix<double, Eigen::RowMajor> build_filter_gradient_part<3>(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>&, const std::vector<Vec<3>>&,
    const std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 3>&);

template <int Dim>
PatternMatrix build_filter_gradient_patterns(const PatternMatrix& symmetric, const std::vector<Vec<Dim>>& position,
                                             const CorrectedOperator<Dim>& gradient) {
  const Index n = symmetric.rows();
  if (gradient.rows() != n) throw SolverError("pressure filter: the gradient and the Laplacian differ in rows");
  // (T G)_I. = sum_d [ sum_{J != I} w_IJd (G_d)_J. + (sum_{J != I} w_IJd) (G_d)_I. ],
  // w_IJd = 1/2 S_IJ (x_J - x_I)_d: a sparse accumulator over the columns of one row.
  std::vector<double> acc(static_cast<std::size_t>(n), 0.0);
  std::vector<char> touched(static_cast<std::size_t>(n), 0);
  std::vector<Index> columns;
  std::vector<double> values;
  PatternMatrix::Builder out(n, n);
  auto add_gradient_row = [&](Index a, int d, double w) {
    const auto r = gradient.row(a);
    for (Index k = r.begin; k < r.end; ++k) {
      const Index m = gradient.source(r, k);
      const auto mu = static_cast<std::size_t>(m);
      if (touched[mu] == 0) {
        touched[mu] = 1;
        columns.push_back(m);
      }
      acc[mu] += w * gradient.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
    }
  };
  for (Index i = 0; i < n; ++i) {
    columns.clear();
    const auto row = symmetric.row(i);
    const auto& xi = position[static_cast<std::size_t>(i)];
    for (int d = 0; d < Dim; ++d) {
      double diag = 0.0;
      for (std::size_t k = 0; k < row.offset.size(); ++k) {
        const Index j = row.base + row.offset[k];
        if (j == i) continue;
        const double w = 0.5 * row.value[k] * (position[static_cast<std::size_t>(j)][d] - xi[d]);
        add_gradient_row(j, d, w);
        diag += w;
      }
      add_gradient_row(i, d, diag);
    }
    std::sort(columns.begin(), columns.end());
    values.clear();
    std::size_t kept = 0;
    for (const Index m : columns) {
      const auto mu = static_cast<std::size_t>(m);
      if (acc[mu] != 0.0) {
        columns[kept++] = m;
        values.push_back(acc[mu]);
      }
      acc[mu] = 0.0;
      touched[mu] = 0;
    }
    columns.resize(kept);
    out.add_row(columns, values);
  }
  return out.finish();
}

template PatternMatrix build_filter_gradient_patterns<1>(const PatternMatrix&, const std::vector<Vec<1>>&,
                                                         const CorrectedOperator<1>&);
template PatternMatrix build_filter_gradient_patterns<2>(const PatternMatrix&, const std::vector<Vec<2>>&,
                                                         const CorrectedOperator<2>&);
template PatternMatrix build_filter_gradient_patterns<3>(const PatternMatrix&, const std::vector<Vec<3>>&,
                                                         const CorrectedOperator<3>&);

template <int Dim>
std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, Dim> gradient_matrices(const CorrectedOperator<Dim>& op,
                                                                                Index columns) {
  std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, Dim> grad;
  for (int d = 0; d < Dim; ++d) {
    std::vector<Eigen::Triplet<double>> t;
    for (Index a = 0; a < op.rows(); ++a) {
      const auto r = op.row(a);
      for (Index k = r.begin; k < r.end; ++k) {
        t.emplace_back(static_cast<int>(a), static_cast<int>(op.source(r, k)),
                       op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)]);
      }
    }
    auto& g = grad[static_cast<std::size_t>(d)];
    g.resize(op.rows(), columns);
    g.setFromTriplets(t.begin(), t.end());
  }
  return grad;
}

template std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 1> gradient_matrices<1>(const CorrectedOperator<1>&,
                                                                                          Index);
template std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 2> gradient_matrices<2>(const CorrectedOperator<2>&,
                                                                                          Index);
template std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, 3> gradient_matrices<3>(const CorrectedOperator<3>&,
                                                                                          Index);

}  // namespace rktsph
