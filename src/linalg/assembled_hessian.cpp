// H assembled per occupied cell into a Tpetra FECrsMatrix: owned and shared rows, shared rows
// exported (summed) to their owners. The graph is built once per set of occupied cells.
#include <Teuchos_TimeMonitor.hpp>
#include <algorithm>

#include "hessian_operator.hpp"

namespace viscompm::linalg {

std::vector<std::vector<int>> node_neighbours(const grid::GridLayout& layout) {
  const int K = layout.nodes_per_cell();
  std::vector<std::vector<int>> neighbours(layout.local_node_count());
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (int a = 0; a < K; ++a) neighbours[nodes[a]].insert(neighbours[nodes[a]].end(), nodes, nodes + K);
  }
  for (auto& nb : neighbours) {
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }
  return neighbours;
}

namespace {
class AssembledHessian : public HessianOperator {
 public:
  explicit AssembledHessian(const NodeSpace& space) : space_(space) {}

  bool update(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    const grid::GridLayout& layout = potential.layout();
    const bool rebuild = matrix_.is_null() || space_.version() != graph_space_version_ ||
                         space_.comm().any(layout.cells != graph_cells_);
    if (rebuild) {
      static const auto graph_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3f newton graph");
      Teuchos::TimeMonitor timer(*graph_timer);
      build_graph(layout);
    }
    fill(potential, v, project);
    return rebuild;
  }
  Teuchos::RCP<const operator_type> op() const override { return matrix_; }
  Teuchos::RCP<crs_matrix_type> matrix() const override { return matrix_; }
  Teuchos::RCP<const vector_type> diagonal() const override {
    auto d = Teuchos::rcp(new vector_type(matrix_->getRowMap()));
    matrix_->getLocalDiagCopy(*d);
    return d;
  }
  std::int64_t nonzeros() const override { return static_cast<std::int64_t>(matrix_->getGlobalNumEntries()); }
  int pattern_builds() const override { return graph_builds_; }

 private:
  void build_graph(const grid::GridLayout& layout);
  void fill(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project);

  const NodeSpace& space_;
  std::vector<NodeId> graph_cells_;  // occupied cells the graph was built for
  std::uint64_t graph_space_version_ = 0;
  int graph_builds_ = 0;
  Teuchos::RCP<fe_graph_type> graph_;
  Teuchos::RCP<fe_matrix_type> matrix_;
  std::vector<local_ordinal_type> local_to_column_;
  // For cell c and stencil nodes (a, b): where node b's three columns start in the rows of node
  // a, relative to the row start (the three rows of a node share one column pattern).
  std::vector<int> cell_offsets_;
};

void AssembledHessian::build_graph(const grid::GridLayout& layout) {
  const auto& s = space_.impl();
  const std::size_t n = layout.local_node_count();
  const int K = layout.nodes_per_cell();
  const auto neighbours = node_neighbours(layout);
  Kokkos::DualView<std::size_t*, fe_graph_type::device_type> counts("entries per row", 3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) counts.h_view(3 * i + d) = 3 * neighbours[i].size();
  counts.modify_host();
  counts.sync_device();

  // Globally indexed: an owner receives columns from the other ranks' shared rows that it does
  // not hold itself, so the column map must come from fillComplete, not from our local nodes.
  graph_ = Teuchos::rcp(new fe_graph_type(s.owned_dof_map, s.local_dof_map,
                                          Kokkos::DualView<const std::size_t*, fe_graph_type::device_type>(counts),
                                          s.dof_import));
  graph_->beginAssembly();
  std::vector<global_ordinal_type> columns;
  const auto& local_dofs = *s.local_dof_map;
  for (std::size_t i = 0; i < n; ++i) {
    columns.clear();
    for (int j : neighbours[i])
      for (int d = 0; d < 3; ++d) columns.push_back(local_dofs.getGlobalElement(3 * j + d));
    for (int d = 0; d < 3; ++d)
      graph_->insertGlobalIndices(local_dofs.getGlobalElement(static_cast<local_ordinal_type>(3 * i + d)),
                                  static_cast<local_ordinal_type>(columns.size()), columns.data());
  }
  graph_->endAssembly();
  matrix_ = Teuchos::rcp(new fe_matrix_type(graph_));

  // Our local dof → column index of the owned+shared matrix that assembly writes into, and each
  // cell's offsets into the CRS rows.
  matrix_->beginAssembly();
  const auto column_map = matrix_->getColMap();
  local_to_column_.resize(3 * n);
  for (std::size_t r = 0; r < 3 * n; ++r)
    local_to_column_[r] = column_map->getLocalElement(local_dofs.getGlobalElement(static_cast<local_ordinal_type>(r)));
  const auto local_matrix = matrix_->getLocalMatrixHost();
  const auto& row_map = local_matrix.graph.row_map;
  const auto& entries = local_matrix.graph.entries;
  cell_offsets_.resize(layout.cell_count() * K * K);
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (int a = 0; a < K; ++a) {
      for (int d = 0; d < 3; ++d) {
        const auto row = 3 * nodes[a] + d;
        const auto* first = entries.data() + row_map(row);
        const auto* last = entries.data() + row_map(row + 1);
        for (int b = 0; b < K; ++b) {
          const local_ordinal_type column = local_to_column_[3 * nodes[b]];
          const auto* at = std::lower_bound(first, last, column);
          if (at + 2 >= last || at[0] != column || at[1] != column + 1 || at[2] != column + 2)
            throw std::logic_error("AssembledHessian: a node's three columns are not contiguous in its rows");
          const int offset = static_cast<int>(at - first);
          if (d == 0) cell_offsets_[(c * K + a) * K + b] = offset;
          else if (cell_offsets_[(c * K + a) * K + b] != offset)
            throw std::logic_error("AssembledHessian: the rows of a node differ in their columns");
        }
      }
    }
  }
  matrix_->endAssembly();
  graph_cells_ = layout.cells;
  graph_space_version_ = space_.version();
  ++graph_builds_;
}

void AssembledHessian::fill(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) {
  const grid::GridLayout& layout = potential.layout();
  matrix_->beginAssembly();
  matrix_->setAllToScalar(0.0);  // beginAssembly keeps old values
  const int K = layout.nodes_per_cell();
  // Element blocks go straight into the values of the owned+shared matrix, at offsets found
  // when the graph was built (no per-entry column search).
  const auto local_matrix = matrix_->getLocalMatrixHost();
  const auto& row_map = local_matrix.graph.row_map;
  double* values = local_matrix.values.data();
  potential.element_hessians(v, project, [&](std::size_t c, const implicit::ElementMatrix& element) {
    const int* nodes = layout.nodes_of_cell(c);
    const int* offsets = cell_offsets_.data() + c * K * K;
    for (int a = 0; a < K; ++a)
      for (int d = 0; d < 3; ++d) {
        // Row 3a+d of the symmetric element is its column 3a+d.
        const double* row_values = element.col(3 * a + d).data();
        double* row = values + row_map(3 * nodes[a] + d);
        for (int b = 0; b < K; ++b) {
          double* target = row + offsets[a * K + b];
          target[0] += row_values[3 * b];
          target[1] += row_values[3 * b + 1];
          target[2] += row_values[3 * b + 2];
        }
      }
  });
  // Inertia: m_i on the diagonal of owned rows.
  for (std::size_t i = 0; i < layout.owned_count; ++i)
    for (int d = 0; d < 3; ++d) {
      const local_ordinal_type row = static_cast<local_ordinal_type>(3 * i + d);
      const double mass = potential.mass()[i];
      matrix_->sumIntoLocalValues(row, 1, &mass, &local_to_column_[row]);
    }
  matrix_->endAssembly();
}
}  // namespace

std::unique_ptr<HessianOperator> make_assembled_hessian(const NodeSpace& space) {
  return std::make_unique<AssembledHessian>(space);
}

}  // namespace viscompm::linalg
