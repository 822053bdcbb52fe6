#include "viscompm/linalg/node_space.hpp"

#include <Teuchos_DefaultMpiComm.hpp>

#include "node_space_impl.hpp"

namespace viscompm::linalg {

namespace {
Teuchos::RCP<const map_type> make_map(const std::vector<global_ordinal_type>& gids,
                                      const Teuchos::RCP<const Teuchos::Comm<int>>& comm) {
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  return Teuchos::rcp(new map_type(invalid, Teuchos::ArrayView<const global_ordinal_type>(gids), 0, comm));
}

}  // namespace

NodeSpace::NodeSpace(const parallel::Communicator& comm) : comm_(comm), impl_(std::make_unique<Impl>()) {
  impl_->comm = Teuchos::rcp(new Teuchos::MpiComm<int>(comm.comm()));
}

NodeSpace::~NodeSpace() = default;

void NodeSpace::update(const parallel::NodePartition& partition) {
  Impl& s = *impl_;
  partition_ = &partition;
  s.owned_count = partition.owned_count();
  s.local_count = partition.local_count();
  const auto& ids = partition.system_ids();
  const auto global_nodes = static_cast<Tpetra::global_size_t>(partition.global_count());
  s.owned_node_map = Teuchos::rcp(new map_type(global_nodes, s.owned_count, 0, s.comm));
  s.owned_dof_map = Teuchos::rcp(new map_type(3 * global_nodes, 3 * s.owned_count, 0, s.comm));
  s.column_node_map = make_map(std::vector<global_ordinal_type>(ids.begin(), ids.end()), s.comm);
  std::vector<global_ordinal_type> dofs(3 * s.local_count);
  for (std::size_t i = 0; i < s.local_count; ++i)
    for (int d = 0; d < 3; ++d) dofs[3 * i + d] = 3 * ids[i] + d;
  s.column_dof_map = make_map(dofs, s.comm);
  // The owners of the ghost columns are known: no directory lookup.
  Teuchos::Array<int> node_owners(partition.ghost_owners().begin(), partition.ghost_owners().end());
  Teuchos::Array<int> dof_owners(3 * node_owners.size());
  for (std::size_t g = 0; g < partition.ghost_owners().size(); ++g)
    for (int d = 0; d < 3; ++d) dof_owners[3 * g + d] = partition.ghost_owners()[g];
  s.node_import = Teuchos::rcp(new import_type(s.owned_node_map, s.column_node_map, node_owners));
  s.dof_import = Teuchos::rcp(new import_type(s.owned_dof_map, s.column_dof_map, dof_owners));
  ++s.version;
}

void NodeSpace::import_ghosts(NodeScalarField& field) const {
  const Impl& s = *impl_;
  vector_type owned(s.owned_node_map), column(s.column_node_map);
  {
    auto view = owned.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < s.owned_count; ++i) view(i, 0) = field[i];
  }
  column.doImport(owned, *s.node_import, Tpetra::INSERT);
  auto view = column.getLocalViewHost(Tpetra::Access::ReadOnly);
  field.resize(s.local_count);
  for (std::size_t i = s.owned_count; i < s.local_count; ++i) field[i] = view(i, 0);
}

void NodeSpace::import_ghosts(NodeVectorField& field) const {
  const Impl& s = *impl_;
  vector_type owned(s.owned_dof_map), column(s.column_dof_map);
  {
    auto view = owned.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < s.owned_count; ++i)
      for (int c = 0; c < 3; ++c) view(3 * i + c, 0) = field[i][c];
  }
  column.doImport(owned, *s.dof_import, Tpetra::INSERT);
  auto view = column.getLocalViewHost(Tpetra::Access::ReadOnly);
  field.resize(s.local_count);
  for (std::size_t i = s.owned_count; i < s.local_count; ++i)
    for (int c = 0; c < 3; ++c) field[i][c] = view(3 * i + c, 0);
}

std::int64_t NodeSpace::global_node_count() const {
  return static_cast<std::int64_t>(impl_->owned_node_map->getGlobalNumElements());
}

std::uint64_t NodeSpace::version() const { return impl_->version; }

}  // namespace viscompm::linalg
