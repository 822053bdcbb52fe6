// Tpetra side of NodeSpace, shared by the linear-algebra translation units.
#pragma once

#include "linalg_types.hpp"
#include "viscompm/linalg/node_space.hpp"

namespace viscompm::linalg {

struct NodeSpace::Impl {
  Teuchos::RCP<const Teuchos::Comm<int>> comm;
  std::size_t owned_count = 0;
  std::size_t local_count = 0;
  std::uint64_t version = 0;
  // The linear system numbers nodes contiguously by rank (node k of rank r: offset_r + k; its
  // dofs 3 (offset_r + k) + d), so the owned maps are contiguous ranges: cheap, and what Amesos2
  // needs (its KLU2 gives wrong answers on maps with gaps).
  Teuchos::RCP<const map_type> owned_node_map, column_node_map;  // one entry per node
  Teuchos::RCP<const map_type> owned_dof_map, column_dof_map;    // 3 per node: gid = 3 system id + d
  Teuchos::RCP<const import_type> node_import, dof_import;       // owned → owned + ghost
};

}  // namespace viscompm::linalg
