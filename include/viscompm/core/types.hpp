// Small dense types used by the physics layer. Physics files include Eigen only.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

namespace viscompm {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Int3 = Eigen::Vector3i;

/// Global particle identifier: stable across frames, restarts and rank counts.
using ParticleId = std::int64_t;
/// Global grid-node identifier: linear index i + nx (j + ny k) over the whole grid.
using NodeId = std::int64_t;

/// A field with one 3-vector per grid node of the local (owned + shared) node set.
using NodeVectorField = std::vector<Vec3>;
/// A field with one scalar per grid node of the local (owned + shared) node set.
using NodeScalarField = std::vector<double>;

/// vec(M) with the column-major convention of Eigen: vec(M)[i + 3 j] = M(i, j).
inline Vec9 vec(const Mat3& m) { return Eigen::Map<const Vec9>(m.data()); }
inline Mat3 unvec(const Vec9& v) { return Eigen::Map<const Mat3>(v.data()); }
inline constexpr int vec_index(int i, int j) { return i + 3 * j; }

}  // namespace viscompm
