// The colliders' surfaces at a frame's time, for the frame file and the XDMF index: every
// collider triangulated in its rest frame (meshes: their own triangles), moved by its rigid
// motion; emitter nozzles follow, numbered after the colliders.
#pragma once

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/io/frame_writer.hpp"

namespace viscompm::io {

/// Fills the collider fields of `extras` for time t; half-spaces are cut to the box [lo, hi].
void add_collider_surfaces(const boundary::Boundary& boundary, double t, const Vec3& lo, const Vec3& hi,
                           FrameExtras& extras);

}  // namespace viscompm::io
