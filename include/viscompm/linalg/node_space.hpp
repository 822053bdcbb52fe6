// Which rank owns which grid node, and moving node data between the copies of a node. Each
// node touched by particles is owned by exactly one of the ranks that touch it (its block owner
// when that rank touches it, else the lowest such rank); the matrix rows follow that ownership.
// Trilinos stays behind this header: Tpetra maps, Import and Export live in the implementation.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/decomposition.hpp"

namespace viscompm::linalg {

class NodeSpace {
 public:
  explicit NodeSpace(const parallel::Communicator& comm);
  ~NodeSpace();
  NodeSpace(const NodeSpace&) = delete;
  NodeSpace& operator=(const NodeSpace&) = delete;

  /// Orders the local nodes of `layout` (owned first, then shared) given the nodes its
  /// particles touch, and indexes its cells. Maps are rebuilt only when some rank's touched
  /// set changed; returns true if they were.
  bool update(const std::vector<NodeId>& touched, const parallel::Decomposition& decomposition,
              grid::GridLayout& layout);

  /// Sums the per-rank partial values of every node; afterwards every copy holds the total.
  void accumulate(NodeScalarField& field) const;
  void accumulate(NodeVectorField& field) const;
  /// Copies each owner's value to the shared copies of its nodes.
  void distribute(NodeVectorField& field) const;

  /// Global number of nodes with particles nearby.
  std::int64_t global_node_count() const;
  /// Incremented every time the maps are rebuilt.
  std::uint64_t version() const;
  const parallel::Communicator& comm() const { return comm_; }

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  parallel::Communicator comm_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
