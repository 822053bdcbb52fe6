// Rebalancing: a recursive coordinate bisection (Zoltan2, hence in the Trilinos layer's RCB with rectilinear cuts) of the
// particle positions into one box per rank, so that every rank holds about as many particles.
#pragma once

#include <memory>

#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::linalg {

/// Boxes of an RCB of `particles` (this rank's) into comm.size() parts (collective).
std::unique_ptr<parallel::BoxDecomposition> make_rcb_decomposition(const parallel::Communicator& comm,
                                                                   const grid::GridGeometry& geometry,
                                                                   const particles::ParticleSet& particles);

}  // namespace viscompm::linalg
