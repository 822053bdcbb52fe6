// Lines of grid nodes: the runs of consecutive nodes along each axis in a set of nodes, cut into
// pieces of at most a given length. A node lies on one line per axis. Line smoothers use them as
// overlapping blocks: a block that spans the thin direction of a stiff plate or rod solves the
// strong coupling across it, which point and node-block relaxation cannot (doc/solvers.md).
#pragma once

#include <cstddef>
#include <vector>

#include "viscompm/core/types.hpp"

namespace viscompm::grid {

/// The lines through `nodes` (grid indices; the result holds positions in `nodes`), axis by axis,
/// each ordered along its axis; runs longer than `max_nodes` are cut into near-equal pieces.
std::vector<std::vector<std::size_t>> node_lines(const std::vector<Int3>& nodes, int max_nodes);

}  // namespace viscompm::grid
