#include "viscompm/linalg/node_space.hpp"

#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_TieBreak.hpp>
#include <algorithm>

#include "node_space_impl.hpp"

namespace viscompm::linalg {

namespace {
// Ownership among the ranks that touch a node: the block owner if it is one of them, else the
// lowest rank.
class PreferBlockOwner : public Tpetra::Details::TieBreak<local_ordinal_type, global_ordinal_type> {
 public:
  PreferBlockOwner(const parallel::Decomposition& d, const grid::GridGeometry& g)
      : decomposition_(d), geometry_(g) {}
  bool mayHaveSideEffects() const override { return false; }
  std::size_t selectedIndex(global_ordinal_type gid,
                            const std::vector<std::pair<int, local_ordinal_type>>& pid_and_lid) const override {
    const int block_owner = decomposition_.owner_of_node(geometry_.node_index(gid));
    std::size_t best = 0;
    for (std::size_t k = 0; k < pid_and_lid.size(); ++k) {
      if (pid_and_lid[k].first == block_owner) return k;
      if (pid_and_lid[k].first < pid_and_lid[best].first) best = k;
    }
    return best;
  }

 private:
  const parallel::Decomposition& decomposition_;
  const grid::GridGeometry& geometry_;
};

Teuchos::RCP<const map_type> make_map(const std::vector<global_ordinal_type>& gids,
                                      const Teuchos::RCP<const Teuchos::Comm<int>>& comm) {
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  return Teuchos::rcp(new map_type(invalid, Teuchos::ArrayView<const global_ordinal_type>(gids), 0, comm));
}

// Copies `data` (n rows of `width` values) in and out of a Tpetra multivector through
// export (ADD into owners) then import (owners to every copy).
void sum_through(const NodeSpace::Impl& s, double* data, std::size_t rows, bool dofs) {
  const auto& local_map = dofs ? s.local_dof_map : s.local_node_map;
  const auto& owned_map = dofs ? s.owned_dof_map : s.owned_node_map;
  multivector_type local(local_map, 1), owned(owned_map, 1);
  {
    auto view = local.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t r = 0; r < rows; ++r) view(r, 0) = data[r];
  }
  owned.doExport(local, dofs ? *s.dof_export : *s.node_export, Tpetra::ADD);
  local.doImport(owned, dofs ? *s.dof_import : *s.node_import, Tpetra::INSERT);
  auto view = local.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t r = 0; r < rows; ++r) data[r] = view(r, 0);
}
}  // namespace

NodeSpace::NodeSpace(const parallel::Communicator& comm) : comm_(comm), impl_(std::make_unique<Impl>()) {
  impl_->comm = Teuchos::rcp(new Teuchos::MpiComm<int>(comm.comm()));
}

NodeSpace::~NodeSpace() = default;

bool NodeSpace::update(const std::vector<NodeId>& touched, const parallel::Decomposition& decomposition,
                       grid::GridLayout& layout) {
  Impl& s = *impl_;
  const bool changed = comm_.any(touched != s.touched) || s.version == 0;
  if (changed) {
    s.touched = touched;
    // Among the ranks touching a node, one becomes its owner.
    const std::vector<global_ordinal_type> touched_gids(touched.begin(), touched.end());
    const auto touched_map = make_map(touched_gids, s.comm);
    const PreferBlockOwner tie_break(decomposition, layout.geometry);
    const auto unique_map = Tpetra::createOneToOne(touched_map, tie_break);
    std::vector<NodeId> owned(unique_map->getNodeElementList().begin(), unique_map->getNodeElementList().end());
    std::sort(owned.begin(), owned.end());
    std::vector<NodeId> shared;
    std::set_difference(touched.begin(), touched.end(), owned.begin(), owned.end(), std::back_inserter(shared));
    s.owned_count = owned.size();
    s.local_nodes = owned;
    s.local_nodes.insert(s.local_nodes.end(), shared.begin(), shared.end());

    // Contiguous system ids: owned nodes numbered after the ranks before; shared nodes learn
    // their owner's numbers through an import keyed by grid id.
    const auto grid_owned = make_map(std::vector<global_ordinal_type>(owned.begin(), owned.end()), s.comm);
    const auto grid_local = make_map(std::vector<global_ordinal_type>(s.local_nodes.begin(), s.local_nodes.end()), s.comm);
    long long count = static_cast<long long>(owned.size()), offset = 0;
    MPI_Exscan(&count, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm_.comm());
    if (comm_.rank() == 0) offset = 0;
    Tpetra::Vector<global_ordinal_type, local_ordinal_type, global_ordinal_type, node_type> owned_ids(grid_owned),
        local_ids(grid_local);
    {
      auto v = owned_ids.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < owned.size(); ++i) v(i, 0) = offset + static_cast<global_ordinal_type>(i);
    }
    local_ids.doImport(owned_ids, import_type(grid_owned, grid_local), Tpetra::INSERT);
    s.local_system_ids.resize(s.local_nodes.size());
    {
      auto v = local_ids.getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t i = 0; i < s.local_nodes.size(); ++i) s.local_system_ids[i] = v(i, 0);
    }
    const auto global_nodes = static_cast<Tpetra::global_size_t>(comm_.sum(static_cast<std::int64_t>(owned.size())));
    s.owned_node_map = Teuchos::rcp(new map_type(global_nodes, owned.size(), 0, s.comm));
    s.local_node_map = make_map(s.local_system_ids, s.comm);
    s.owned_dof_map = Teuchos::rcp(new map_type(3 * global_nodes, 3 * owned.size(), 0, s.comm));
    std::vector<global_ordinal_type> local_dofs(3 * s.local_nodes.size());
    for (std::size_t i = 0; i < s.local_nodes.size(); ++i)
      for (int d = 0; d < 3; ++d) local_dofs[3 * i + d] = 3 * s.local_system_ids[i] + d;
    s.local_dof_map = make_map(local_dofs, s.comm);
    s.node_export = Teuchos::rcp(new export_type(s.local_node_map, s.owned_node_map));
    s.dof_export = Teuchos::rcp(new export_type(s.local_dof_map, s.owned_dof_map));
    s.node_import = Teuchos::rcp(new import_type(s.owned_node_map, s.local_node_map));
    s.dof_import = Teuchos::rcp(new import_type(s.owned_dof_map, s.local_dof_map));
    ++s.version;
  }
  layout.nodes = s.local_nodes;
  layout.owned_count = s.owned_count;
  grid::index_cell_nodes(layout);
  return changed;
}

void NodeSpace::accumulate(NodeScalarField& field) const {
  sum_through(*impl_, field.data(), field.size(), false);
}

void NodeSpace::accumulate(NodeVectorField& field) const {
  sum_through(*impl_, field.data()->data(), 3 * field.size(), true);
}

void NodeSpace::distribute(NodeVectorField& field) const {
  const Impl& s = *impl_;
  multivector_type owned(s.owned_dof_map, 1), local(s.local_dof_map, 1);
  const double* data = field.data()->data();
  {
    auto view = owned.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t r = 0; r < 3 * s.owned_count; ++r) view(r, 0) = data[r];
  }
  local.doImport(owned, *s.dof_import, Tpetra::INSERT);
  auto view = local.getLocalViewHost(Tpetra::Access::ReadOnly);
  double* out = field.data()->data();
  for (std::size_t r = 0; r < 3 * field.size(); ++r) out[r] = view(r, 0);
}

std::int64_t NodeSpace::global_node_count() const {
  return static_cast<std::int64_t>(impl_->owned_node_map->getGlobalNumElements());
}

std::uint64_t NodeSpace::version() const { return impl_->version; }

}  // namespace viscompm::linalg
