#include "viscompm/grid/node_lines.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace viscompm::grid {

std::vector<std::vector<std::size_t>> node_lines(const std::vector<Int3>& nodes, int max_nodes) {
  std::vector<std::vector<std::size_t>> lines;
  std::vector<std::size_t> order(nodes.size());
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    // Nodes sorted by the other two indices, then along the axis: lines are consecutive runs.
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
      return std::make_tuple(nodes[i][a], nodes[i][b], nodes[i][axis]) <
             std::make_tuple(nodes[j][a], nodes[j][b], nodes[j][axis]);
    });
    std::size_t begin = 0;
    while (begin < order.size()) {
      std::size_t end = begin + 1;
      while (end < order.size() && nodes[order[end]][a] == nodes[order[begin]][a] &&
             nodes[order[end]][b] == nodes[order[begin]][b] &&
             nodes[order[end]][axis] == nodes[order[end - 1]][axis] + 1)
        ++end;
      // The run [begin, end) in pieces of near-equal length, none longer than max_nodes.
      const std::size_t length = end - begin, cap = static_cast<std::size_t>(std::max(1, max_nodes));
      const std::size_t pieces = (length + cap - 1) / cap;
      for (std::size_t k = 0; k < pieces; ++k) {
        const std::size_t from = begin + k * length / pieces, to = begin + (k + 1) * length / pieces;
        lines.emplace_back(order.begin() + static_cast<std::ptrdiff_t>(from), order.begin() + static_cast<std::ptrdiff_t>(to));
      }
      begin = end;
    }
  }
  return lines;
}

}  // namespace viscompm::grid
