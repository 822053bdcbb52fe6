// MatrixMarket files of Newton systems (private to src/linalg).
#pragma once

#include "viscompm/linalg/linalg_types.hpp"

namespace viscompm::linalg {

/// Writes A and b to PREFIX.mtx and PREFIX_rhs.mtx with rows renumbered 0..n-1 in the order of
/// the row map across ranks (our dof ids 3·node + d are sparse, which MatrixMarket cannot hold).
void write_contiguous_matrix_market(const crs_matrix_type& A, const multivector_type& b, const std::string& prefix);

}  // namespace viscompm::linalg
