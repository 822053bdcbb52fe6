// Stiff bodies: the connected pieces of material whose elastic waves cross many cells in one time
// step (c Δt/Δx at least a threshold), e.g. the slices of the pie's crust between their soft cuts
// or a stiff block falling into jelly. In the Newton matrix H = M + Δt² K such a body's rigid
// motions cost only its mass and the soft material around it, far less than any deformation of
// it: they are H's softest modes, and a grid hierarchy whose coarse functions straddle the soft
// gaps between bodies cannot represent them. The linear solver adds them to its coarse space
// (linalg: Deflation = stiff bodies). Found on the particles' cells, the same on any rank count.
#pragma once

#include <utility>
#include <vector>

#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/parallel/communicator.hpp"

namespace viscompm::implicit {

struct StiffBodies {
  int count = 0;               ///< bodies, on every rank
  std::vector<Vec3> centroids;  ///< per body: the mean of its cells' centres
  /// (local node, body) for every local node a stiff cell of the body reaches (its particles'
  /// stencils), sorted; a node between two bodies is listed for both.
  std::vector<std::pair<int, int>> node_bodies;
};

/// The stiff bodies of `potential`: cells (own and ghost) whose particles are more than half (by
/// mass) of materials with c Δt/Δx ≥ `elastic_cfl` (c the material's fastest elastic wave),
/// joined through shared faces into bodies; bodies beyond the `max_bodies` largest are left out.
/// Collective.
StiffBodies find_stiff_bodies(const IncrementalPotential& potential, double elastic_cfl, int max_bodies,
                              const parallel::Communicator& comm);

}  // namespace viscompm::implicit
