#pragma once
// V3: the effective-stress condition at impermeable faces that carry a total stress, taken
// implicitly in the pressure step (method-notes §2.4, eqs. (2.4.15)-(2.4.17)).
//
// At such a face node T the effective normal stress is held at sigma'_kk = sigmabar_kk + p_T
// (eq. (4.1.3)). Steps 1-2 see it with p^n: the nodal v* then carries a term linear in the face
// pressures, v* = v*'' + B p^n, that the pressure step does not know about, and the undrained
// stiffness feeds back explicitly through it (the old limit C c_u/c_d <= 3.5). Here B is built
// from the very operators steps 1-2 use, so that the pressure step can take the condition at
// t^{n+1}: v^{n+1} = v* + B (p^{n+1} - p^n) - (dt/rho) G p^{n+1}, and the storage equation gains
// the matrix A = S_w D B (columns at the face nodes only) on both sides.
#include <vector>

#include <Eigen/SparseCore>

#include "particles/field.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
struct FacePressureCoupling {
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  /// The face node of each coupling (a node and a held normal component; a corner has two).
  std::vector<Index> face_node;
  /// B, entry by entry: v*_I[axis] gains value * p_T per unit pressure at the coupling's node T
  /// (m/s per Pa), from the interpolation to the stress points, the divergence back to the
  /// nodes and the difference form of fix (a) at the held components.
  struct Entry {
    Index node;
    int axis;
    Index coupling;
    double value;
  };
  std::vector<Entry> entries;
  /// A = S_w D B as a node x node matrix (1/(Pa s)), its columns at the face nodes.
  Sparse storage_matrix;

  bool empty() const { return face_node.empty(); }
  std::size_t bytes() const {
    return face_node.size() * sizeof(Index) + entries.size() * sizeof(Entry) +
           static_cast<std::size_t>(storage_matrix.nonZeros()) * (sizeof(double) + sizeof(int)) +
           static_cast<std::size_t>(storage_matrix.outerSize() + 1) * sizeof(int);
  }
  /// v += B (p_new - p_old).
  void add_velocity(FieldView<double, Dim> v, const double* p_new, const double* p_old) const;
};

/// The couplings of every node that is not drained and holds a normal total stress, with B
/// and A from the model's operators (step 1's interpolation, step 2's divergence and difference
/// form) and the node -> node divergence `node_operator` of the pressure step.
template <int Dim>
FacePressureCoupling<Dim> build_face_pressure_coupling(const StaggeredModel<Dim>& model,
                                                       const std::vector<bool>& drained,
                                                       const CorrectedOperator<Dim>& node_operator, double dt,
                                                       double saturation);

}  // namespace rktsph
