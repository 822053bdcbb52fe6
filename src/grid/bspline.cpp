#include "viscompm/grid/bspline.hpp"

#include <cmath>

#include "viscompm/core/error.hpp"

namespace viscompm::grid {

std::string kernel_name(KernelOrder order) {
  return order == KernelOrder::quadratic ? "quadratic" : "cubic";
}

double bspline_value(KernelOrder order, double r) {
  const double a = std::abs(r);
  if (order == KernelOrder::quadratic) {
    if (a < 0.5) return 0.75 - a * a;
    if (a < 1.5) return 0.5 * (1.5 - a) * (1.5 - a);
    return 0.0;
  }
  // Cubic N(x) of §3.1.
  if (a < 1.0) return 0.5 * a * a * a - a * a + 2.0 / 3.0;
  if (a < 2.0) return -a * a * a / 6.0 + a * a - 2.0 * a + 4.0 / 3.0;
  return 0.0;
}

double bspline_derivative(KernelOrder order, double r) {
  const double a = std::abs(r);
  const double s = r < 0.0 ? -1.0 : 1.0;
  if (order == KernelOrder::quadratic) {
    if (a < 0.5) return -2.0 * r;
    if (a < 1.5) return -s * (1.5 - a);
    return 0.0;
  }
  if (a < 1.0) return s * (1.5 * a * a - 2.0 * a);
  if (a < 2.0) return s * (-0.5 * a * a + 2.0 * a - 2.0);
  return 0.0;
}

Int3 stencil_base(KernelOrder order, const Vec3& xi) {
  Int3 base;
  for (int d = 0; d < 3; ++d) {
    base[d] = order == KernelOrder::quadratic ? static_cast<int>(std::floor(xi[d] - 0.5))
                                              : static_cast<int>(std::floor(xi[d])) - 1;
  }
  return base;
}

Stencil make_stencil(KernelOrder order, const Vec3& origin, double dx, const Vec3& x) {
  const Vec3 xi = (x - origin) / dx;
  Stencil s;
  s.base = stencil_base(order, xi);
  const int width = stencil_width(order);
  for (int d = 0; d < 3; ++d) {
    for (int a = 0; a < width; ++a) {
      const double r = xi[d] - static_cast<double>(s.base[d] + a);
      s.weight[d][a] = bspline_value(order, r);
      s.weight_gradient[d][a] = bspline_derivative(order, r) / dx;
    }
  }
  return s;
}

}  // namespace viscompm::grid
