#pragma once
// Schwaiger's corrected SPH Laplacian on the node set (METHOD.md §3.5), for the pore-pressure
// equation of the V3 saturated solver (METHOD.md §2.4, §5.3).
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
// Neumann (impermeable) walls: at a node on a wall with outward normal n the prescribed normal
// derivative (zero) replaces the computed one in the correction, i.e. grad f_I is projected on
// the wall's tangent plane, P = I - n n. The row then evaluates the Laplacian of the even
// (mirror) extension of f across the wall - the discrete counterpart of dp/dn = 0
// (METHOD.md §4.1: mirror nodes carrying p_mirror = p across straight walls).
//
// Symmetric part (for the SPD matrix of the PCG, METHOD.md §3.5 "recommended approach"):
//   S_IJ = 1/2 (c_I + c_J) * 1/2 (V_I + V_J) * (-F_IJ)  (J != I),  S_II = -sum_J S_IJ,
// the Brookshaw sum with symmetrised weights. S is symmetric negative semi-definite (a weighted
// graph Laplacian). The difference L - S is applied to the previous pressure (deferred
// correction) by the pore-pressure solver.
#include <vector>

#include <Eigen/SparseCore>

#include "core/kernel.hpp"
#include "core/types.hpp"
#include "geometry/particles.hpp"

namespace rktsph {

template <int Dim>
struct NodeLaplacian {
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  Sparse full;       // Schwaiger-corrected L (not symmetric), 1/m^2
  Sparse symmetric;  // symmetric Brookshaw part S, 1/m^2
  std::vector<double> c;  // normalisation c_I = (2/n_d) tr A_I^{-1}
  Index degenerate_rows = 0;  // rows whose A_I was singular (c_I = 2, no gradient correction)
};

/// Build L and S over `nodes`. `wall_axes[I]` (may be empty) holds, per node, bit d set when
/// the node lies on an impermeable wall with normal e_d (the normal gradient is then zero).
template <int Dim>
NodeLaplacian<Dim> build_node_laplacian(const ParticleSet<Dim>& nodes,
                                        const CubicSplineKernel<Dim>& kernel,
                                        const std::vector<std::uint8_t>& wall_axes = {});

}  // namespace rktsph
