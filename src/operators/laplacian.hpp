#pragma once
// Schwaiger's corrected SPH Laplacian on the node set (method-notes §3.5), for the pore-pressure
// equation of the V3 saturated solver (method-notes §2.4, §5.3).
//
// With F_IJ = W'(r_IJ)/r_IJ (< 0), the CSPM matrix A_I = sum_J V_J grad_I W_IJ (x) (x_J - x_I)
// (= -Gamma_I), c_I = (2/n_d) tr A_I^{-1} and g_I = sum_J V_J grad_I W_IJ:
//
//   lap f_I = c_I [ sum_J V_J (f_I - f_J) F_IJ - grad f_I . g_I ],
//   grad f_I = A_I^{-1} sum_J V_J (f_J - f_I) grad_I W_IJ          (CSPM, exact for linear f)
//
// so that, written as rows, L_IJ = c_I V_J [-F_IJ - g_I . A_I^{-1} grad_I W_IJ] (J != I) and
// L_II = -sum_J L_IJ (zero row sum). L is exact for linear fields on any particle set whose A_I
// is invertible, and second-order accurate in the interior of a lattice. It is not symmetric.
//
// Neumann (impermeable) walls, two ways. The solver uses MIRROR images (below: `mirrors`), the
// even extension across straight walls. The simpler `wall_axes` variant (kept for comparison
// and tested in 1D) only fixes the gradient: at a node on a wall with outward normal n the prescribed normal
// derivative (zero) replaces the computed one in the correction, i.e. grad f_I is projected on
// the wall's tangent plane, P = I - n n. The row then evaluates the Laplacian of the even
// (mirror) extension of f across the wall - the discrete counterpart of dp/dn = 0
// (method-notes §4.1: mirror nodes carrying p_mirror = p across straight walls).
//
// Symmetric part (for the SPD matrix of the PCG, method-notes §3.5 "recommended approach"):
//   S_IJ = 1/2 (c_I + c_J) * 1/2 (V_I + V_J) * (-F_IJ)  (J != I),  S_II = -sum_J S_IJ,
// the Brookshaw sum with symmetrised weights. S is symmetric negative semi-definite (a weighted
// graph Laplacian). The difference L - S is applied to the previous pressure (deferred
// correction) by the pore-pressure solver.
#include <array>
#include <span>
#include <vector>

#include <Eigen/SparseCore>

#include "core/kernel.hpp"
#include "core/types.hpp"
#include "linear_solvers/pattern_matrix.hpp"
#include "neighbours/relation.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

/// An impermeable straight wall x_axis = coord, the body on the side opposite to `outward`
/// (+1: outward normal +e_axis). Neighbours are mirrored across it (even extension, p_J' = p_J,
/// method-notes §4.1), which restores a full support near the wall.
struct MirrorPlane {
  int axis = 0;
  double coord = 0.0;
  int outward = 1;
};

template <int Dim>
struct NodeLaplacian {
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  Sparse full;                // Schwaiger-corrected L (not symmetric), 1/m^2
  Sparse symmetric;           // symmetric Brookshaw part S, 1/m^2
  std::vector<double> c;      // normalisation c_I = (2/n_d) tr A_I^{-1}
  Index degenerate_rows = 0;  // rows whose A_I was singular (c_I = 2, no gradient correction)
};

/// Build L and S over `nodes`. `wall_axes[I]` (may be empty) holds, per node, bit d set when
/// the node lies on an impermeable wall with normal e_d (the normal gradient is then zero).
/// `mirrors` (may be empty): impermeable walls whose mirror images join the sums of every node
/// within the kernel support of the wall (a neighbour ON the wall is its own image and so
/// counts twice: it stands for its real and its mirrored half-volume). With mirrors, a row
/// next to a wall sees a full support: A_I ~ 1 and the isotropic normalisation of Schwaiger's
/// formula holds, which it does not for a one-sided, anisotropic support (method-notes §3.5
/// table: 2.25 instead of 4 at an edge). Images across two walls (corners) are not added.
/// `mirror_mask[I]` (may be empty = all) selects, bit k, the planes mirrors[k] used at node I
/// (at most 8 planes), so that a plane that is impermeable only in part (a footing on a drained
/// surface) mirrors only where it is a wall.
template <int Dim>
NodeLaplacian<Dim> build_node_laplacian(const Relation<Dim>& relation, const ParticleSet<Dim>& nodes,
                                        const CubicSplineKernel<Dim>& kernel,
                                        const std::vector<std::uint8_t>& wall_axes = {},
                                        const std::vector<MirrorPlane>& mirrors = {},
                                        const std::vector<std::uint8_t>& mirror_mask = {});
/// The relation build_node_laplacian sums over: node pairs within the support, rows in the cell
/// list's order.
template <int Dim>
RelationOptions laplacian_relation_options(const CubicSplineKernel<Dim>& kernel);
/// L and S stored by shared row patterns (linear_solvers/pattern_matrix.hpp), built row by row
/// with mirror walls (the pressure solver's set-up): about 10 bytes per node on a lattice where
/// the CSR pair costs 700. The entries are those of build_node_laplacian to the patterns'
/// sharing tolerance. `with_full` = false skips L (the pressure filter needs S only).
struct NodeLaplacianPatterns {
  PatternMatrix full;
  PatternMatrix symmetric;
  std::vector<double> c;
  Index degenerate_rows = 0;
};
template <int Dim>
NodeLaplacianPatterns build_node_laplacian_patterns(const Relation<Dim>& relation, const ParticleSet<Dim>& nodes,
                                                    const CubicSplineKernel<Dim>& kernel,
                                                    const std::vector<MirrorPlane>& mirrors = {},
                                                    const std::vector<std::uint8_t>& mirror_mask = {},
                                                    bool with_full = true);

/// The same, with the relation built here.
template <int Dim>
NodeLaplacian<Dim> build_node_laplacian(const ParticleSet<Dim>& nodes, const CubicSplineKernel<Dim>& kernel,
                                        const std::vector<std::uint8_t>& wall_axes = {},
                                        const std::vector<MirrorPlane>& mirrors = {},
                                        const std::vector<std::uint8_t>& mirror_mask = {});

/// The explicit half of the linear-exact pressure filter (the delta-SPH diffusion of Antuono et
/// al. 2010, written on the symmetric Brookshaw weights S_IJ of `symmetric`):
///
///   F p_I = sum_J S_IJ psi_IJ,   psi_IJ = (p_J - p_I) - 1/2 (grad p_I + grad p_J) . (x_J - x_I),
///
/// = (S p)_I - (T G p)_I. Returns T G, given the corrected gradient G as one sparse matrix per
/// axis (`gradient[d]`, rows and columns the nodes). psi_IJ vanishes for linear fields wherever G
/// is exact (every row of a CSPM gradient, walls included) and for quadratic fields wherever G is
/// exact for them (the interior of a lattice), so F acts on odd-even modes (G p ~ 0, psi_IJ =
/// p_J - p_I) and not on the smooth gradient a load imposes at a wall.
template <int Dim>
Eigen::SparseMatrix<double, Eigen::RowMajor> build_filter_gradient_part(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& symmetric, const std::vector<Vec<Dim>>& position,
    const std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, Dim>& gradient);

/// The same T G, row by row from the pattern-stored S and the corrected node gradient itself
/// (no gradient matrices, no sparse-sparse product), stored by shared row patterns.
template <int Dim>
PatternMatrix build_filter_gradient_patterns(const PatternMatrix& symmetric, const std::vector<Vec<Dim>>& position,
                                             const CorrectedOperator<Dim>& gradient);

/// The gradient weights of a corrected operator as one sparse matrix per axis (rows its targets,
/// `columns` its sources): (G_d f)_a = sum_k grad[k][d] f_{source(a, k)}.
template <int Dim>
std::array<Eigen::SparseMatrix<double, Eigen::RowMajor>, Dim> gradient_matrices(const CorrectedOperator<Dim>& op,
                                                                                Index columns);

}  // namespace rktsph
