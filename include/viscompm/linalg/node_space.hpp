// The Tpetra view of a NodePartition: maps of the owned nodes and dofs (contiguous system ids,
// 3 dofs per node, all on the node's owner), column maps of owned then ghost nodes, and the
// Imports that copy owners' values to the ghost copies. Built once per partition, reused by
// every step while the partition lives. Trilinos stays behind this header.
#pragma once

#include <cstdint>
#include <memory>

#include "viscompm/core/types.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/node_partition.hpp"

namespace viscompm::linalg {

class NodeSpace {
 public:
  explicit NodeSpace(const parallel::Communicator& comm);
  ~NodeSpace();
  NodeSpace(const NodeSpace&) = delete;
  NodeSpace& operator=(const NodeSpace&) = delete;

  /// Builds the maps and Imports of `partition` (collective). Call again when the partition is
  /// rebuilt; version() then increments.
  void update(const parallel::NodePartition& partition);

  /// Copies each owner's value to the ghost copies of its nodes (collective).
  void import_ghosts(NodeScalarField& field) const;
  void import_ghosts(NodeVectorField& field) const;

  const parallel::NodePartition& partition() const { return *partition_; }
  /// Global number of nodes in the system.
  std::int64_t global_node_count() const;
  /// Incremented every time update() builds new maps.
  std::uint64_t version() const;
  const parallel::Communicator& comm() const { return comm_; }

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  parallel::Communicator comm_;
  const parallel::NodePartition* partition_ = nullptr;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
