// The implicit face condition of the V3 pressure step (schemes/face_pressure_coupling.hpp,
// method-notes §2.4 eqs. (2.4.15)-(2.4.17)). Built once: the particles do not move in V3.
#include "schemes/face_pressure_coupling.hpp"

#include <map>
#include <utility>

namespace rktsph {

template <int Dim>
void FacePressureCoupling<Dim>::add_velocity(FieldView<double, Dim> v, const double* p_new,
                                             const double* p_old) const {
  for (const Entry& e : entries) {
    const auto t = static_cast<std::size_t>(face_node[static_cast<std::size_t>(e.coupling)]);
    v(e.node, e.axis) += e.value * (p_new[t] - p_old[t]);
  }
}

template <int Dim>
FacePressureCoupling<Dim> build_face_pressure_coupling(const StaggeredModel<Dim>& m, const std::vector<bool>& drained,
                                                       const CorrectedOperator<Dim>& node_operator, double dt,
                                                       double saturation) {
  FacePressureCoupling<Dim> out;
  const Index nn = m.nodes.size();
  const NodalConstraints<Dim>& con = m.constraints;
  // A normal stress component held at node i (constraint component Dim + k holds sigma_kk).
  auto holds_normal = [&](Index i, int k) {
    for (Index q = con.begin(i); q < con.end(i); ++q)
      if (con[q].component == Dim + k) return true;
    return false;
  };
  std::vector<int> coupling_axis;
  std::map<std::pair<Index, int>, Index> coupling_of;  // (node, axis) -> coupling
  for (const Index i : con.constrained()) {
    if (drained[static_cast<std::size_t>(i)]) continue;  // p is prescribed there: no feedback
    for (int k = 0; k < Dim; ++k) {
      if (!holds_normal(i, k)) continue;
      coupling_of[{i, k}] = static_cast<Index>(out.face_node.size());
      out.face_node.push_back(i);
      coupling_axis.push_back(k);
    }
  }
  if (out.face_node.empty()) return out;

  // Step 1: sigma_E = sum_J w_EJ sigma_J, so a unit p at a face node reaches the stress points
  // of its support with the interpolation weights.
  const CorrectedOperator<Dim>& to_sp = m.to_stress_points;
  std::vector<std::vector<std::pair<Index, double>>> at_stress_point(static_cast<std::size_t>(m.stress_points.size()));
  for (Index e = 0; e < m.stress_points.size(); ++e) {
    const auto r = to_sp.row(e);
    for (Index q = r.begin; q < r.end; ++q) {
      const Index j = to_sp.source(r, q);
      for (int k = 0; k < Dim; ++k) {
        const auto it = coupling_of.find({j, k});
        if (it != coupling_of.end())
          at_stress_point[static_cast<std::size_t>(e)].emplace_back(it->second, to_sp.interp[static_cast<std::size_t>(q)]);
      }
    }
  }
  // Step 2: dv_I[k] = (dt/rho_I) d(sigma_kk)/dx_k, by the corrected gradient, or at a held
  // component by the difference form sum_E c_IE sigma_E - (sum_E c_IE) fhat with fhat = sigmabar + p_I.
  const CorrectedOperator<Dim>& to_nodes = m.to_nodes;
  const DifferenceGradient<Dim>& diff = m.constrained_gradient;
  std::map<std::pair<int, Index>, double> row;  // (axis, coupling) -> value, one node at a time
  for (Index i = 0; i < nn; ++i) {
    row.clear();
    const Index dr = con.constrained_row(i);
    const auto r = to_nodes.row(i);
    for (Index q = r.begin; q < r.end; ++q) {
      for (const auto& [c, w] : at_stress_point[static_cast<std::size_t>(to_nodes.source(r, q))]) {
        const int k = coupling_axis[static_cast<std::size_t>(c)];
        if (dr >= 0 && holds_normal(i, k)) continue;  // the difference form below replaces it
        row[{k, c}] += to_nodes.grad[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)] * w;
      }
    }
    if (dr >= 0) {
      const auto d = static_cast<std::size_t>(dr);
      for (Index q = diff.row_start[d]; q < diff.row_start[d + 1]; ++q) {
        for (const auto& [c, w] : at_stress_point[static_cast<std::size_t>(diff.source[static_cast<std::size_t>(q)])]) {
          const int k = coupling_axis[static_cast<std::size_t>(c)];
          if (holds_normal(i, k)) row[{k, c}] += diff.weight[static_cast<std::size_t>(q)][k] * w;
        }
      }
      for (int k = 0; k < Dim; ++k) {
        const auto it = coupling_of.find({i, k});
        if (it != coupling_of.end()) row[{k, it->second}] -= diff.weight_sum[d][k];
      }
    }
    const double f = dt / m.nodes.density[static_cast<std::size_t>(i)];
    for (const auto& [key, value] : row) {
      if (value != 0.0) out.entries.push_back({i, key.first, key.second, f * value});
    }
  }

  // A = S_w D B: the pressure step's node divergence of the velocity response.
  std::vector<std::vector<std::size_t>> by_node(static_cast<std::size_t>(nn));  // entries of B per node
  for (std::size_t n = 0; n < out.entries.size(); ++n) by_node[static_cast<std::size_t>(out.entries[n].node)].push_back(n);
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> a;
  for (Index j = 0; j < nn; ++j) {
    const auto r = node_operator.row(j);
    for (Index q = r.begin; q < r.end; ++q) {
      const Index i = node_operator.source(r, q);
      for (const std::size_t n : by_node[static_cast<std::size_t>(i)]) {
        const auto& e = out.entries[n];
        const double g = node_operator.grad[static_cast<std::size_t>(q)][static_cast<std::size_t>(e.axis)];
        a.emplace_back(j, out.face_node[static_cast<std::size_t>(e.coupling)], saturation * g * e.value);
      }
    }
  }
  out.storage_matrix.resize(nn, nn);
  out.storage_matrix.setFromTriplets(a.begin(), a.end());
  return out;
}

template struct FacePressureCoupling<1>;
template struct FacePressureCoupling<2>;
template struct FacePressureCoupling<3>;
template FacePressureCoupling<1> build_face_pressure_coupling<1>(const StaggeredModel<1>&, const std::vector<bool>&,
                                                                 const CorrectedOperator<1>&, double, double);
template FacePressureCoupling<2> build_face_pressure_coupling<2>(const StaggeredModel<2>&, const std::vector<bool>&,
                                                                 const CorrectedOperator<2>&, double, double);
template FacePressureCoupling<3> build_face_pressure_coupling<3>(const StaggeredModel<3>&, const std::vector<bool>&,
                                                                 const CorrectedOperator<3>&, double, double);

}  // namespace rktsph
