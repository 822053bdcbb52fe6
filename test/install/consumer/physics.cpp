// Uses the installed physics layer: the quadratic B-spline weights of a particle sum to 1.
#include <cstdio>

#include "viscompm/grid/bspline.hpp"

int main() {
  using namespace viscompm;
  const grid::Stencil s = grid::make_stencil(grid::KernelOrder::quadratic, Vec3::Zero(), 0.1, Vec3(0.33, 0.46, 0.51));
  double sum = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) sum += s.w(a, b, c);
  std::printf("B-spline weights sum to %.15f\n", sum);
  return sum > 1.0 - 1e-12 && sum < 1.0 + 1e-12 ? 0 : 1;
}
