#include "viscompm/linalg/newton_system.hpp"

#include <MatrixMarket_Tpetra.hpp>
#include <Teuchos_TimeMonitor.hpp>
#include <algorithm>
#include <chrono>

#include "krylov.hpp"
#include "node_space_impl.hpp"

namespace viscompm::linalg {

struct NewtonSystem::Impl {
  Impl(const NodeSpace& s, const SolverConfiguration& c)
      : space(s), config(c), preconditioner(make_preconditioner(c)), krylov(c) {}

  const NodeSpace& space;
  SolverConfiguration config;
  std::unique_ptr<Preconditioner> preconditioner;
  KrylovSolver krylov;

  std::vector<NodeId> graph_cells;  // occupied cells the graph was built for
  std::uint64_t graph_space_version = 0;
  int graph_builds = 0;
  bool pattern_changed = true;      // since the last preconditioner set-up
  bool values_changed = true;
  double assembly_seconds = 0.0;
  Teuchos::RCP<fe_graph_type> graph;
  Teuchos::RCP<fe_matrix_type> matrix;
  NearNullspace modes;
  std::vector<local_ordinal_type> local_to_column;
  // For cell c and stencil nodes (a, b): where node b's three columns start in the rows of node
  // a, relative to the row start (the three rows of a node share one column pattern).
  std::vector<int> cell_offsets;

  void build_graph(const grid::GridLayout& layout);
  void build_near_nullspace(const grid::GridLayout& layout);
};

void NewtonSystem::Impl::build_graph(const grid::GridLayout& layout) {
  const auto& s = space.impl();
  const std::size_t n = layout.local_node_count();
  const int K = layout.nodes_per_cell();
  // Neighbours of every local node: the union of the stencils of the cells containing it.
  std::vector<std::vector<int>> neighbours(n);
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (int a = 0; a < K; ++a) neighbours[nodes[a]].insert(neighbours[nodes[a]].end(), nodes, nodes + K);
  }
  Kokkos::DualView<std::size_t*, fe_graph_type::device_type> counts("entries per row", 3 * n);
  auto host_counts = counts.h_view;
  for (std::size_t i = 0; i < n; ++i) {
    auto& nb = neighbours[i];
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    for (int d = 0; d < 3; ++d) host_counts(3 * i + d) = 3 * nb.size();
  }
  counts.modify_host();
  counts.sync_device();

  // Globally indexed: an owner receives columns from the other ranks' shared rows that it does
  // not hold itself, so the column map must come from fillComplete, not from our local nodes.
  graph = Teuchos::rcp(new fe_graph_type(s.owned_dof_map, s.local_dof_map,
                                         Kokkos::DualView<const std::size_t*, fe_graph_type::device_type>(counts),
                                         s.dof_import));
  graph->beginAssembly();
  std::vector<global_ordinal_type> columns;
  const auto& local_dofs = *s.local_dof_map;
  for (std::size_t i = 0; i < n; ++i) {
    columns.clear();
    for (int j : neighbours[i])
      for (int d = 0; d < 3; ++d) columns.push_back(local_dofs.getGlobalElement(3 * j + d));
    for (int d = 0; d < 3; ++d)
      graph->insertGlobalIndices(local_dofs.getGlobalElement(static_cast<local_ordinal_type>(3 * i + d)),
                                 static_cast<local_ordinal_type>(columns.size()), columns.data());
  }
  graph->endAssembly();
  matrix = Teuchos::rcp(new fe_matrix_type(graph));
  // Our local dof → column index of the owned+shared matrix that assembly writes into.
  matrix->beginAssembly();
  const auto column_map = matrix->getColMap();
  local_to_column.resize(3 * n);
  for (std::size_t r = 0; r < 3 * n; ++r)
    local_to_column[r] = column_map->getLocalElement(local_dofs.getGlobalElement(static_cast<local_ordinal_type>(r)));
  const auto local_matrix = matrix->getLocalMatrixHost();
  const auto& row_map = local_matrix.graph.row_map;
  const auto& entries = local_matrix.graph.entries;
  cell_offsets.resize(layout.cell_count() * K * K);
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (int a = 0; a < K; ++a) {
      for (int d = 0; d < 3; ++d) {
        const auto row = 3 * nodes[a] + d;
        const auto* first = entries.data() + row_map(row);
        const auto* last = entries.data() + row_map(row + 1);
        for (int b = 0; b < K; ++b) {
          const local_ordinal_type column = local_to_column[3 * nodes[b]];
          const auto* at = std::lower_bound(first, last, column);
          if (at + 2 >= last || at[0] != column || at[1] != column + 1 || at[2] != column + 2)
            throw std::logic_error("NewtonSystem: a node's three columns are not contiguous in its rows");
          const int offset = static_cast<int>(at - first);
          if (d == 0) cell_offsets[(c * K + a) * K + b] = offset;
          else if (cell_offsets[(c * K + a) * K + b] != offset)
            throw std::logic_error("NewtonSystem: the rows of a node differ in their columns");
        }
      }
    }
  }
  matrix->endAssembly();
  graph_cells = layout.cells;
  graph_space_version = space.version();
  ++graph_builds;
  pattern_changed = true;
  build_near_nullspace(layout);
}

void NewtonSystem::Impl::build_near_nullspace(const grid::GridLayout& layout) {
  const auto& s = space.impl();
  modes.coordinates = Teuchos::rcp(new multivector_type(s.owned_node_map, 3));
  modes.rigid_body_modes = Teuchos::rcp(new multivector_type(s.owned_dof_map, 6));
  auto xyz = modes.coordinates->getLocalViewHost(Tpetra::Access::OverwriteAll);
  auto rbm = modes.rigid_body_modes->getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (std::size_t i = 0; i < layout.owned_count; ++i) {
    const Vec3 x = layout.geometry.node_position(layout.nodes[i]);
    for (int d = 0; d < 3; ++d) xyz(i, d) = x[d];
    for (int d = 0; d < 3; ++d) {
      for (int m = 0; m < 6; ++m) rbm(3 * i + d, m) = 0.0;
      rbm(3 * i + d, d) = 1.0;  // translations
    }
    // Rotations about the axes: e_a × x.
    rbm(3 * i + 1, 3) = -x.z(); rbm(3 * i + 2, 3) = x.y();
    rbm(3 * i + 0, 4) = x.z();  rbm(3 * i + 2, 4) = -x.x();
    rbm(3 * i + 0, 5) = -x.y(); rbm(3 * i + 1, 5) = x.x();
  }
}

NewtonSystem::NewtonSystem(const NodeSpace& space, const SolverConfiguration& config)
    : impl_(std::make_unique<Impl>(space, config)) {}

NewtonSystem::~NewtonSystem() = default;

void NewtonSystem::assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v,
                            bool project) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  const grid::GridLayout& layout = potential.layout();
  const bool rebuild = m.graph.is_null() || m.space.version() != m.graph_space_version ||
                       m.space.comm().any(layout.cells != m.graph_cells);
  if (rebuild) {
    static const auto graph_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3f newton graph");
    Teuchos::TimeMonitor timer(*graph_timer);
    m.build_graph(layout);
  }

  m.matrix->beginAssembly();
  m.matrix->setAllToScalar(0.0);  // beginAssembly keeps old values
  const int K = layout.nodes_per_cell();
  // Element blocks go straight into the values of the owned+shared matrix, at offsets found
  // when the graph was built (no per-entry column search).
  const auto local_matrix = m.matrix->getLocalMatrixHost();
  const auto& row_map = local_matrix.graph.row_map;
  double* values = local_matrix.values.data();
  potential.element_hessians(v, project, [&](std::size_t c, const implicit::ElementMatrix& element) {
    const int* nodes = layout.nodes_of_cell(c);
    const int* offsets = m.cell_offsets.data() + c * K * K;
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
      m.matrix->sumIntoLocalValues(row, 1, &mass, &m.local_to_column[row]);
    }
  m.matrix->endAssembly();
  m.values_changed = true;
  m.assembly_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

LinearSolveReport NewtonSystem::solve(const NodeVectorField& rhs, NodeVectorField& dv) {
  Impl& m = *impl_;
  const auto& s = m.space.impl();
  multivector_type b(s.owned_dof_map, 1), x(s.owned_dof_map, 1);
  {
    auto view = b.getLocalViewHost(Tpetra::Access::OverwriteAll);
    const double* data = rhs.data()->data();
    for (std::size_t r = 0; r < 3 * s.owned_count; ++r) view(r, 0) = data[r];
  }
  static const auto setup_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3b newton precondition");
  static const auto cg_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3c newton cg");
  double setup_seconds = 0.0;
  if (m.values_changed) {
    Teuchos::TimeMonitor timer(*setup_timer);
    const auto start = std::chrono::steady_clock::now();
    m.preconditioner->setup(m.matrix, m.pattern_changed, m.modes);
    setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.pattern_changed = false;
    m.values_changed = false;
  }
  LinearSolveReport report;
  {
    Teuchos::TimeMonitor timer(*cg_timer);
    report = m.krylov.solve(m.matrix, m.preconditioner->op(), x, b);
  }
  report.setup_seconds = setup_seconds;
  dv.assign(rhs.size(), Vec3::Zero());
  {
    auto view = x.getLocalViewHost(Tpetra::Access::ReadOnly);
    double* data = dv.data()->data();
    for (std::size_t r = 0; r < 3 * s.owned_count; ++r) data[r] = view(r, 0);
  }
  m.space.distribute(dv);
  return report;
}

std::int64_t NewtonSystem::global_rows() const {
  return static_cast<std::int64_t>(impl_->matrix->getGlobalNumRows());
}

std::int64_t NewtonSystem::global_nonzeros() const {
  return static_cast<std::int64_t>(impl_->matrix->getGlobalNumEntries());
}

double NewtonSystem::assembly_seconds() const { return impl_->assembly_seconds; }
int NewtonSystem::graph_builds() const { return impl_->graph_builds; }
const SolverConfiguration& NewtonSystem::configuration() const { return impl_->config; }

std::vector<std::tuple<long long, long long, double>> NewtonSystem::gather_entries() const {
  const auto& A = *impl_->matrix;
  std::vector<double> local;  // (row, column, value) triplets as doubles (exact below 2^53)
  const auto row_map = A.getRowMap();
  const auto col_map = A.getColMap();
  for (std::size_t r = 0; r < A.getNodeNumRows(); ++r) {
    typename crs_matrix_type::local_inds_host_view_type cols;
    typename crs_matrix_type::values_host_view_type vals;
    A.getLocalRowView(static_cast<local_ordinal_type>(r), cols, vals);
    for (std::size_t k = 0; k < cols.extent(0); ++k) {
      local.push_back(static_cast<double>(row_map->getGlobalElement(r)));
      local.push_back(static_cast<double>(col_map->getGlobalElement(cols(k))));
      local.push_back(vals(k));
    }
  }
  const MPI_Comm comm = impl_->space.comm().comm();
  int count = static_cast<int>(local.size()), ranks = impl_->space.comm().size();
  std::vector<int> counts(ranks), offsets(ranks, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(offsets.back() + counts.back());
  MPI_Allgatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  std::vector<std::tuple<long long, long long, double>> entries;
  for (std::size_t k = 0; k + 2 < all.size(); k += 3)
    entries.emplace_back(static_cast<long long>(all[k]), static_cast<long long>(all[k + 1]), all[k + 2]);
  std::sort(entries.begin(), entries.end());
  return entries;
}

void NewtonSystem::write_matrix_market(const std::string& file) const {
  Tpetra::MatrixMarket::Writer<crs_matrix_type>::writeSparseFile(file, impl_->matrix);
}

}  // namespace viscompm::linalg
