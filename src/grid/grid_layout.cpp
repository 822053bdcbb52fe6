#include "viscompm/grid/grid_layout.hpp"

namespace viscompm::grid {

Mat3 GridLayout::gradient(std::size_t c, std::size_t p, const NodeVectorField& f) const {
  Mat3 sum = Mat3::Zero();
  for_each_stencil_node(*this, c, p,
                        [&](int, int i, double, const Vec3& dw) { sum += f[i] * dw.transpose(); });
  return sum;
}

}  // namespace viscompm::grid
