// Rebalancing: a recursive coordinate bisection (Zoltan2's RCB with rectilinear cuts) of the
// particle positions into one box per rank, so that every rank holds about as many particles.
#pragma once

#include <memory>

#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::parallel {

/// Boxes of an RCB of `particles` (this rank's) into comm.size() parts (collective).
std::unique_ptr<BoxDecomposition> make_rcb_decomposition(const Communicator& comm, const grid::GridGeometry& geometry,
                                                         const particles::ParticleSet& particles);

}  // namespace viscompm::parallel
