// Tpetra side of NodeSpace, shared by the linear-algebra translation units.
#pragma once

#include "viscompm/linalg/linalg_types.hpp"
#include "viscompm/linalg/node_space.hpp"

namespace viscompm::linalg {

struct NodeSpace::Impl {
  Teuchos::RCP<const Teuchos::Comm<int>> comm;
  std::vector<NodeId> touched;     // last touched set (to detect changes)
  std::vector<NodeId> local_nodes; // grid ids: owned first, then shared
  std::size_t owned_count = 0;
  // The linear system numbers nodes contiguously by rank (node k of rank r: offset_r + k; its
  // dofs 3 (offset_r + k) + d), so the maps are contiguous ranges: cheap, and what Amesos2
  // needs (its KLU2 gives wrong answers on maps with gaps).
  std::vector<global_ordinal_type> local_system_ids;
  std::uint64_t version = 0;

  Teuchos::RCP<const map_type> owned_node_map, local_node_map;  // one entry per node (system ids)
  Teuchos::RCP<const map_type> owned_dof_map, local_dof_map;    // 3 per node: gid = 3 system id + d
  Teuchos::RCP<const export_type> node_export, dof_export;      // local → owned
  Teuchos::RCP<const import_type> node_import, dof_import;      // owned → local
};

}  // namespace viscompm::linalg
