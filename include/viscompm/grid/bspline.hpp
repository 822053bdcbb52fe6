// B-spline interpolation kernels of §3.1: the quadratic one used by the SCA paper's scenes and
// the cubic N(x) given in §3.1. A particle's stencil is the tensor product of 1D weights.
#pragma once

#include <array>
#include <string>

#include "viscompm/core/types.hpp"

namespace viscompm::grid {

enum class KernelOrder { quadratic = 2, cubic = 3 };

/// Number of nodes per dimension a particle touches (3 quadratic, 4 cubic).
constexpr int stencil_width(KernelOrder order) { return order == KernelOrder::quadratic ? 3 : 4; }
/// Number of nodes a particle touches in 3D.
constexpr int stencil_size(KernelOrder order) {
  return stencil_width(order) * stencil_width(order) * stencil_width(order);
}
/// The APIC inertia-like tensor D_p = d Δx² I (Jiang et al. 2015): d = 1/4 quadratic, 1/3 cubic.
constexpr double apic_inertia_factor(KernelOrder order) {
  return order == KernelOrder::quadratic ? 0.25 : 1.0 / 3.0;
}

std::string kernel_name(KernelOrder order);

/// 1D kernel N(r) and its derivative dN/dr, r in cell units.
double bspline_value(KernelOrder order, double r);
double bspline_derivative(KernelOrder order, double r);

/// One particle's interpolation stencil: first node index per dimension and the 1D weights and
/// weight derivatives (derivatives in physical units, i.e. already divided by Δx).
struct Stencil {
  Int3 base = Int3::Zero();
  std::array<std::array<double, 4>, 3> weight{};
  std::array<std::array<double, 4>, 3> weight_gradient{};

  /// w_ip for the stencil node with per-dimension offsets (a, b, c).
  double w(int a, int b, int c) const { return weight[0][a] * weight[1][b] * weight[2][c]; }
  /// ∇w_ip for the stencil node with offsets (a, b, c).
  Vec3 grad_w(int a, int b, int c) const {
    return {weight_gradient[0][a] * weight[1][b] * weight[2][c],
            weight[0][a] * weight_gradient[1][b] * weight[2][c],
            weight[0][a] * weight[1][b] * weight_gradient[2][c]};
  }
};

/// First stencil node per dimension for a position in cell units ξ = (x - origin)/Δx.
Int3 stencil_base(KernelOrder order, const Vec3& xi);

/// Stencil of a particle at x for a grid with lower corner `origin` and spacing `dx`.
Stencil make_stencil(KernelOrder order, const Vec3& origin, double dx, const Vec3& x);

}  // namespace viscompm::grid
