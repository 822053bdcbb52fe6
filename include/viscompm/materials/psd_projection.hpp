// Projection of a small symmetric matrix onto the positive semi-definite cone (negative
// eigenvalues clamped to zero), so the assembled Newton matrix is SPD and CG applies.
#pragma once

#include "viscompm/core/types.hpp"

namespace viscompm::materials {

/// Replaces `h` by its nearest PSD matrix in the Frobenius norm. A matrix that is already PSD
/// (no eigenvalue below −1e-12 of the largest, i.e. rounding) is returned unchanged, bit for bit.
/// Returns true if anything was clamped.
bool project_to_psd(Mat9& h);

}  // namespace viscompm::materials
