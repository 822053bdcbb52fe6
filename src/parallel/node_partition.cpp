#include "viscompm/parallel/node_partition.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace viscompm::parallel {

NodeBox::NodeBox(const Int3& lower, const Int3& upper_inclusive, int fill)
    : lower_(lower), extent_((upper_inclusive - lower + Int3::Ones()).cwiseMax(0)) {
  values_.assign(static_cast<std::size_t>(extent_.x()) * extent_.y() * extent_.z(), fill);
}

namespace {
// Calls f(ijk) for every node of the box [lower, upper] (inclusive), x fastest.
template <class F>
void for_each_node(const Int3& lower, const Int3& upper, F&& f) {
  for (int z = lower.z(); z <= upper.z(); ++z)
    for (int y = lower.y(); y <= upper.y(); ++y)
      for (int x = lower.x(); x <= upper.x(); ++x) f(Int3(x, y, z));
}
}  // namespace

NodePartition::NodePartition(const Communicator& comm, const grid::GridGeometry& geometry, grid::KernelOrder order,
                             const Decomposition& decomposition, const std::vector<PaddedCell>& own_cells)
    : geometry_(geometry), order_(order), decomposition_(&decomposition), rank_(comm.rank()) {
  window_radius_ = grid::stencil_width(order) - 1;
  const int width = 2 * window_radius_ + 1;
  window_size_ = width * width * width;
  find_owned_nodes(comm, decomposition, own_cells);
  find_ghost_nodes(comm, decomposition);
  build_rows();
}

void NodePartition::find_owned_nodes(const Communicator& comm, const Decomposition& decomposition,
                                     const std::vector<PaddedCell>& own_cells) {
  const int reach = grid::stencil_width(order_) - 1;
  const Int3 last_node = geometry_.cells;
  // Padded nodes: the stencils of every cell within each occupied cell's padding.
  std::vector<NodeId> padded;
  if (!own_cells.empty()) {
    Int3 lower = Int3::Constant(std::numeric_limits<int>::max()), upper = Int3::Constant(-1);
    auto node_range = [&](const PaddedCell& c, Int3& lo, Int3& hi) {
      const Int3 base = geometry_.node_index(c.cell);
      lo = (base - c.pad_below).cwiseMax(0);
      hi = (base + c.pad_above + Int3::Constant(reach)).cwiseMin(last_node);
    };
    for (const PaddedCell& c : own_cells) {
      Int3 lo, hi;
      node_range(c, lo, hi);
      lower = lower.cwiseMin(lo);
      upper = upper.cwiseMax(hi);
    }
    NodeBox marks(lower, upper, 0);
    for (const PaddedCell& c : own_cells) {
      Int3 lo, hi;
      node_range(c, lo, hi);
      for (int z = lo.z(); z <= hi.z(); ++z)
        for (int y = lo.y(); y <= hi.y(); ++y) {
          int* row = &marks.at(Int3(lo.x(), y, z));
          std::fill(row, row + (hi.x() - lo.x() + 1), 1);
        }
    }
    for_each_node(lower, upper, [&](const Int3& ijk) {
      if (marks.at(ijk)) padded.push_back(geometry_.node_id(ijk));
    });
  }
  // Each padded node goes to the rank whose block contains it.
  std::vector<NodeId> owned;
  if (comm.size() == 1) {
    owned = std::move(padded);
  } else {
    std::vector<std::vector<NodeId>> outgoing(comm.size());
    for (const NodeId id : padded) {
      const int owner = decomposition.owner_of_node(geometry_.node_index(id));
      if (owner == rank_) owned.push_back(id);
      else outgoing[owner].push_back(id);
    }
    for (const auto& incoming : comm.exchange(outgoing)) owned.insert(owned.end(), incoming.begin(), incoming.end());
    std::sort(owned.begin(), owned.end());
    owned.erase(std::unique(owned.begin(), owned.end()), owned.end());
  }
  nodes_ = std::move(owned);
  owned_count_ = nodes_.size();
  long long count = static_cast<long long>(owned_count_), offset = 0;
  MPI_Exscan(&count, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());
  if (comm.rank() == 0) offset = 0;
  global_count_ = comm.sum(static_cast<std::int64_t>(owned_count_));
  system_ids_.resize(owned_count_);
  for (std::size_t k = 0; k < owned_count_; ++k) system_ids_[k] = offset + static_cast<std::int64_t>(k);
}

void NodePartition::find_ghost_nodes(const Communicator& comm, const Decomposition& decomposition) {
  const int R = window_radius_;
  if (owned_count_ == 0) {
    local_index_ = NodeBox();
    owner_ = NodeBox();
  } else {
    Int3 lower = geometry_.node_index(nodes_.front()), upper = lower;
    for (std::size_t k = 0; k < owned_count_; ++k) {
      const Int3 ijk = geometry_.node_index(nodes_[k]);
      lower = lower.cwiseMin(ijk);
      upper = upper.cwiseMax(ijk);
    }
    lower = (lower - Int3::Constant(R)).cwiseMax(0);
    upper = (upper + Int3::Constant(R)).cwiseMin(geometry_.cells);
    local_index_ = NodeBox(lower, upper, -1);
    for (std::size_t k = 0; k < owned_count_; ++k) local_index_.at(geometry_.node_index(nodes_[k])) = static_cast<int>(k);
    if (comm.size() > 1) {
      owner_ = NodeBox(lower, upper, 0);
      for_each_node(lower, upper, [&](const Int3& ijk) { owner_.at(ijk) = decomposition.owner_of_node(ijk); });
    }
  }
  if (comm.size() == 1) return;

  // Every owned node whose window reaches another rank's nodes is sent there with its system id:
  // it is a column of that rank's rows (windows are symmetric).
  std::vector<std::vector<std::int64_t>> outgoing(comm.size());
  std::vector<int> sent_to;
  for (std::size_t k = 0; k < owned_count_; ++k) {
    const Int3 ijk = geometry_.node_index(nodes_[k]);
    const Int3 lo = (ijk - Int3::Constant(R)).cwiseMax(0), hi = (ijk + Int3::Constant(R)).cwiseMin(geometry_.cells);
    sent_to.clear();
    for_each_node(lo, hi, [&](const Int3& j) {
      const int o = owner_.at(j);
      if (o != rank_ && std::find(sent_to.begin(), sent_to.end(), o) == sent_to.end()) {
        sent_to.push_back(o);
        outgoing[o].push_back(nodes_[k]);
        outgoing[o].push_back(system_ids_[k]);
      }
    });
  }
  const auto incoming = comm.exchange(outgoing);
  // Keep the nodes whose windows hold an owned node; order them by owner, then id (the column
  // order Tpetra's Import and MueLu expect).
  struct Ghost {
    int owner;
    NodeId id;
    std::int64_t system_id;
  };
  std::vector<Ghost> ghosts;
  for (int source = 0; source < comm.size(); ++source)
    for (std::size_t k = 0; k + 1 < incoming[source].size(); k += 2) {
      const NodeId id = incoming[source][k];
      const Int3 ijk = geometry_.node_index(id);
      if (!local_index_.contains(ijk)) continue;
      const Int3 lo = (ijk - Int3::Constant(R)).cwiseMax(0), hi = (ijk + Int3::Constant(R)).cwiseMin(geometry_.cells);
      bool reaches_owned = false;
      for_each_node(lo, hi, [&](const Int3& j) {
        const int lid = local_index_.get(j, -1);
        reaches_owned = reaches_owned || (lid >= 0 && static_cast<std::size_t>(lid) < owned_count_);
      });
      if (reaches_owned) ghosts.push_back({source, id, incoming[source][k + 1]});
    }
  std::sort(ghosts.begin(), ghosts.end(),
            [](const Ghost& a, const Ghost& b) { return a.owner != b.owner ? a.owner < b.owner : a.id < b.id; });
  for (const Ghost& g : ghosts) {
    local_index_.at(geometry_.node_index(g.id)) = static_cast<int>(nodes_.size());
    nodes_.push_back(g.id);
    system_ids_.push_back(g.system_id);
    ghost_owners_.push_back(g.owner);
  }
}

void NodePartition::build_rows() {
  const int R = window_radius_;
  row_begin_.assign(1, 0);
  row_columns_.clear();
  window_slots_.assign(owned_count_ * window_size_, -1);
  std::vector<std::pair<int, int>> entries;  // (local column, window position)
  for (std::size_t i = 0; i < owned_count_; ++i) {
    const Int3 ijk = geometry_.node_index(nodes_[i]);
    entries.clear();
    int position = 0;
    for (int dz = -R; dz <= R; ++dz)
      for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx, ++position) {
          const Int3 j = ijk + Int3(dx, dy, dz);
          const int lid = local_index_.get(j, -1);
          if (lid >= 0) entries.emplace_back(lid, position);
        }
    std::sort(entries.begin(), entries.end());
    std::int16_t* slots = window_slots_.data() + i * window_size_;
    for (std::size_t s = 0; s < entries.size(); ++s) {
      row_columns_.push_back(entries[s].first);
      slots[entries[s].second] = static_cast<std::int16_t>(s);
    }
    row_begin_.push_back(row_columns_.size());
  }
}

int NodePartition::owner(const Int3& ijk) const {
  if (owner_.extent().isZero()) return rank_;
  if (!owner_.contains(ijk)) throw std::logic_error("NodePartition::owner: node out of reach");
  return owner_.at(ijk);
}

bool NodePartition::covers(const std::vector<NodeId>& cells, std::size_t first, std::size_t last) const {
  const int width = grid::stencil_width(order_);
  for (std::size_t c = first; c < last; ++c) {
    const Int3 base = geometry_.node_index(cells[c]);
    for (int z = 0; z < width; ++z)
      for (int y = 0; y < width; ++y)
        for (int x = 0; x < width; ++x)
          if (local_index(base + Int3(x, y, z)) < 0) return false;
  }
  return true;
}

void NodePartition::index_cells(const std::vector<NodeId>& cells, std::size_t first, std::size_t last,
                                std::vector<int>& cell_nodes) const {
  const int width = grid::stencil_width(order_);
  const int per_cell = width * width * width;
  cell_nodes.resize(last * per_cell);
  for (std::size_t c = first; c < last; ++c) {
    const Int3 base = geometry_.node_index(cells[c]);
    int k = 0;
    for (int z = 0; z < width; ++z)
      for (int y = 0; y < width; ++y)
        for (int x = 0; x < width; ++x, ++k) {
          const int lid = local_index(base + Int3(x, y, z));
          if (lid < 0) throw std::logic_error("NodePartition: a stencil node is not in the partition");
          cell_nodes[c * per_cell + k] = lid;
        }
  }
}

}  // namespace viscompm::parallel
