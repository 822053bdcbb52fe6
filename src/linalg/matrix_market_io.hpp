// MatrixMarket files of Newton systems (private to src/linalg).
#pragma once

#include "linalg_types.hpp"

namespace viscompm::linalg {

/// Writes A, b and the node coordinates (one row of x, y, z per owned node) to PREFIX.mtx,
/// PREFIX_rhs.mtx and PREFIX_coordinates.mtx, with rows renumbered 0..n-1 in the order of the
/// row map across ranks (3 per node, node-major).
void write_contiguous_matrix_market(const crs_matrix_type& A, const multivector_type& b,
                                    const multivector_type& coordinates, const std::string& prefix);

}  // namespace viscompm::linalg
