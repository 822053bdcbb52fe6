#include "viscompm/parallel/grid_hierarchy.hpp"

#include <algorithm>
#include <unordered_map>

namespace viscompm::parallel {

namespace {
struct Parent {
  int index;
  double weight;
};

// The coarse parents of fine index x along one axis; the coarse index of the node on fine index
// 2k is k + shift (shift 1 leaves room for the B-spline's parent below fine index 0).
int axis_parents(Prolongation kind, int x, int shift, Parent* out) {
  int n = 0;
  auto add = [&](int index, double weight) { out[n++] = {index + shift, weight}; };
  if (kind == Prolongation::piecewise_constant) {
    add(x / 2, 1.0);
  } else if (x % 2 == 0) {
    if (kind == Prolongation::trilinear) {
      add(x / 2, 1.0);
    } else {
      add(x / 2 - 1, 0.125);
      add(x / 2, 0.75);
      add(x / 2 + 1, 0.125);
    }
  } else {
    add((x - 1) / 2, 0.5);
    add((x + 1) / 2, 0.5);
  }
  return n;
}

NodeId linear_id(const Int3& ijk, const Int3& dims) {
  return ijk.x() + static_cast<NodeId>(dims.x()) * (ijk.y() + static_cast<NodeId>(dims.y()) * ijk.z());
}

Int3 index_of(NodeId id, const Int3& dims) {
  const NodeId nx = dims.x(), ny = dims.y();
  return Int3(static_cast<int>(id % nx), static_cast<int>((id / nx) % ny), static_cast<int>(id / (nx * ny)));
}

using ParentRow = std::vector<std::pair<NodeId, double>>;

// The parents of every owned fine node with their weights: the rows of P, by coarse grid id.
std::vector<ParentRow> parent_rows(Prolongation kind, const std::vector<Int3>& fine, int shift, const Int3& coarse_dims) {
  std::vector<ParentRow> rows(fine.size());
  Parent px[3], py[3], pz[3];
  for (std::size_t k = 0; k < fine.size(); ++k) {
    const int nx = axis_parents(kind, fine[k].x(), shift, px);
    const int ny = axis_parents(kind, fine[k].y(), shift, py);
    const int nz = axis_parents(kind, fine[k].z(), shift, pz);
    for (int a = 0; a < nz; ++a)
      for (int b = 0; b < ny; ++b)
        for (int d = 0; d < nx; ++d)
          rows[k].emplace_back(linear_id(Int3(px[d].index, py[b].index, pz[a].index), coarse_dims),
                               px[d].weight * py[b].weight * pz[a].weight);
  }
  return rows;
}

// The coarse nodes of `c`: every parent goes to its owner, the owned ones (received or kept) are
// numbered contiguously by rank, and the ghost parents learn their system ids from their owners
// (collective).
void own_parents(const Communicator& comm, const std::vector<ParentRow>& rows,
                 const std::function<int(const Int3&)>& owner_of, CoarseLevel& c) {
  std::vector<NodeId> referenced;
  for (const auto& row : rows)
    for (const auto& [id, w] : row) referenced.push_back(id);
  std::sort(referenced.begin(), referenced.end());
  referenced.erase(std::unique(referenced.begin(), referenced.end()), referenced.end());
  std::vector<std::vector<NodeId>> outgoing(comm.size());
  std::vector<NodeId> owned;
  for (const NodeId id : referenced) {
    const int referenced_owner = comm.size() == 1 ? 0 : owner_of(index_of(id, c.dimensions));
    if (referenced_owner == comm.rank()) owned.push_back(id);
    else outgoing[referenced_owner].push_back(id);
  }
  if (comm.size() > 1) {
    for (const auto& incoming : comm.exchange(outgoing)) owned.insert(owned.end(), incoming.begin(), incoming.end());
    std::sort(owned.begin(), owned.end());
    owned.erase(std::unique(owned.begin(), owned.end()), owned.end());
  }
  c.nodes = owned;
  c.owned_count = owned.size();
  long long count = static_cast<long long>(owned.size()), offset = 0;
  MPI_Exscan(&count, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());
  if (comm.rank() == 0) offset = 0;
  c.global_count = comm.sum(static_cast<std::int64_t>(owned.size()));
  for (std::size_t k = 0; k < owned.size(); ++k) c.system_ids.push_back(offset + static_cast<std::int64_t>(k));
  if (comm.size() == 1) return;
  // Ghost parents: ask their owners for their system ids (the requests were the `outgoing` lists).
  const auto requests = comm.exchange(outgoing);
  std::vector<std::vector<std::int64_t>> answers(comm.size());
  for (int r = 0; r < comm.size(); ++r)
    for (const NodeId id : requests[r]) {
      const auto it = std::lower_bound(owned.begin(), owned.end(), id);
      answers[r].push_back(offset + static_cast<std::int64_t>(it - owned.begin()));
    }
  const auto replies = comm.exchange(answers);
  // Ghosts by owner, then id: the outgoing lists are sorted by id within each owner.
  for (int r = 0; r < comm.size(); ++r)
    for (std::size_t k = 0; k < outgoing[r].size(); ++k) {
      c.nodes.push_back(outgoing[r][k]);
      c.system_ids.push_back(replies[r][k]);
      c.ghost_owners.push_back(r);
    }
}

// The rows of P with local column indices, ascending.
void local_rows(const std::vector<ParentRow>& rows, CoarseLevel& c) {
  std::unordered_map<NodeId, int> local;
  local.reserve(c.nodes.size());
  for (std::size_t k = 0; k < c.nodes.size(); ++k) local.emplace(c.nodes[k], static_cast<int>(k));
  c.row_begin.assign(1, 0);
  std::vector<std::pair<int, double>> entries;
  for (const auto& row : rows) {
    entries.clear();
    for (const auto& [id, w] : row) entries.emplace_back(local.at(id), w);
    std::sort(entries.begin(), entries.end());
    for (const auto& [column, w] : entries) {
      c.columns.push_back(column);
      c.weights.push_back(w);
    }
    c.row_begin.push_back(c.columns.size());
  }
}

// One coarsening: the coarse level under a fine level (its owned nodes' indices `fine`) whose
// node 0 sits on level-0 index `fine_origin`.
CoarseLevel coarsen(const Communicator& comm, const Int3& fine_dims, int fine_origin, const std::vector<Int3>& fine,
                    int level, const Int3& level0_last, const std::function<int(const Int3&)>& owner,
                    Prolongation kind) {
  CoarseLevel c;
  const int shift = kind == Prolongation::quadratic_bspline ? 1 : 0;
  c.spacing = 1 << level;
  c.origin = fine_origin - shift * c.spacing;
  c.dimensions = fine_dims.unaryExpr([shift](int n) { return n / 2 + 1 + 2 * shift; });
  auto owner_of = [&](const Int3& ijk) {
    return owner((Int3::Constant(c.origin) + c.spacing * ijk).cwiseMax(0).cwiseMin(level0_last));
  };
  const std::vector<ParentRow> rows = parent_rows(kind, fine, shift, c.dimensions);
  own_parents(comm, rows, owner_of, c);
  local_rows(rows, c);
  return c;
}
}  // namespace

std::vector<CoarseLevel> build_grid_hierarchy(const Communicator& comm, const Int3& fine_dimensions,
                                              const std::vector<Int3>& owned_fine,
                                              const std::function<int(const Int3&)>& owner,
                                              const HierarchySettings& settings) {
  std::vector<CoarseLevel> levels;
  const Int3 level0_last = fine_dimensions - Int3::Ones();
  Int3 dims = fine_dimensions;
  int origin = 0;
  std::vector<Int3> fine = owned_fine;
  std::int64_t count = comm.sum(static_cast<std::int64_t>(fine.size()));
  // Down to Coarsest nodes, and at least one coarse level above the smallest systems: a lone
  // fine level would make the "multigrid" its smoother alone.
  for (int level = 1; level < settings.max_levels &&
                      (count > settings.coarsest_nodes || (levels.empty() && count > settings.always_coarsen_above));
       ++level) {
    levels.push_back(coarsen(comm, dims, origin, fine, level, level0_last, owner, settings.prolongation));
    const CoarseLevel& c = levels.back();
    // Coarsening must make progress (a level of one node per rank cannot shrink further).
    if (c.global_count >= count) {
      levels.pop_back();
      break;
    }
    dims = c.dimensions;
    origin = c.origin;
    fine.clear();
    for (std::size_t k = 0; k < c.owned_count; ++k) fine.push_back(index_of(c.nodes[k], dims));
    count = c.global_count;
  }
  return levels;
}

}  // namespace viscompm::parallel
