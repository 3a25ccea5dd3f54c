#pragma once
// Basic types shared by every part of the solver core.
//
// Conventions (method-notes §1.1): SI units, stress positive in tension, p = -tr(sigma)/3
// positive in compression. The stress tensor is always carried in full: the out-of-plane
// normal component szz in plane strain and the lateral components syy, szz in 1D uniaxial
// strain are state variables, never dropped.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <Eigen/Core>

namespace rktsph {

using Index = std::int32_t;  // particle index; 2^31 particles is beyond one shared-memory run

template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;
template <int Dim>
using Mat = Eigen::Matrix<double, Dim, Dim>;

/// Number of stress components carried per particle: normal components first, then the
/// in-plane shears. 1D: (xx, yy, zz); 2D: (xx, yy, zz, xy); 3D: (xx, yy, zz, xy, yz, xz).
template <int Dim>
inline constexpr int kStressComponents = Dim == 1 ? 3 : (Dim == 2 ? 4 : 6);

/// A full symmetric tensor in the 3D Voigt order (xx, yy, zz, xy, yz, xz), tensor (not
/// engineering) shear components. Materials work on this form whatever the dimension.
using Sym6 = std::array<double, 6>;

enum class StressComponent : int { xx = 0, yy = 1, zz = 2, xy = 3, yz = 4, xz = 5 };

inline constexpr std::array<std::string_view, 6> kStressComponentNames = {"xx", "yy", "zz", "xy", "yz", "xz"};
inline constexpr std::array<std::string_view, 3> kAxisNames = {"x", "y", "z"};

/// Index of a 3D Voigt component in the per-dimension stress storage, or -1 if the
/// component is identically zero in that dimension (e.g. xy in 1D, yz in 2D).
template <int Dim>
constexpr int stress_slot(StressComponent c) {
  const int i = static_cast<int>(c);
  if (i < 3) return i;
  if constexpr (Dim == 1) return -1;
  if constexpr (Dim == 2) return i == 3 ? 3 : -1;
  return i;
}

/// Slot of the tensor component (k, d) (axes k, d < Dim) in the per-dimension stress storage.
template <int Dim>
constexpr int stress_slot(int k, int d) {
  if (k == d) return k;
  const int lo = k < d ? k : d, hi = k < d ? d : k;
  if (lo == 0 && hi == 1) return 3;
  if (lo == 1 && hi == 2) return 4;
  return 5;
}

/// Expand the per-dimension stress storage into the full 3D Voigt form.
template <int Dim>
inline Sym6 to_sym6(const double* s) {
  Sym6 out{s[0], s[1], s[2], 0.0, 0.0, 0.0};
  if constexpr (Dim >= 2) out[3] = s[3];
  if constexpr (Dim == 3) {
    out[4] = s[4];
    out[5] = s[5];
  }
  return out;
}

/// Store the components of a full Voigt tensor that exist in this dimension.
template <int Dim>
inline void from_sym6(const Sym6& in, double* s) {
  for (int i = 0; i < kStressComponents<Dim>; ++i) s[i] = in[static_cast<std::size_t>(i)];
}

/// Mean pressure p = -tr(sigma)/3 (positive in compression) and von Mises q = sqrt(3 J2).
struct Invariants {
  double p;
  double q;
};
Invariants invariants(const Sym6& s);

}  // namespace rktsph
