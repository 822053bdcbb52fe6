// Tpetra side of NodeSpace, shared by the linear-algebra translation units.
#pragma once

#include "viscompm/linalg/linalg_types.hpp"
#include "viscompm/linalg/node_space.hpp"

namespace viscompm::linalg {

struct NodeSpace::Impl {
  Teuchos::RCP<const Teuchos::Comm<int>> comm;
  std::vector<NodeId> touched;     // last touched set (to detect changes)
  std::vector<NodeId> local_nodes; // owned first, then shared
  std::size_t owned_count = 0;
  std::uint64_t version = 0;

  Teuchos::RCP<const map_type> owned_node_map, local_node_map;  // one entry per node
  Teuchos::RCP<const map_type> owned_dof_map, local_dof_map;    // 3 per node: gid = 3 node + d
  Teuchos::RCP<const export_type> node_export, dof_export;      // local → owned
  Teuchos::RCP<const import_type> node_import, dof_import;      // owned → local
};

}  // namespace viscompm::linalg
