// H assembled into a Tpetra CrsMatrix, owner computes: a rank fills its owned rows completely
// from its particles and the ghost copies of its neighbours' particles, so no value crosses a
// rank. The graph is the partition's node windows, built from local arrays (row offsets, local
// column indices; no global-index insertion, sorting or communication) and kept while the
// partition lives; each assembly only refills the values, at offsets found from the window
// position of every node pair of a cell.
#include <stdexcept>
#include <algorithm>

#include "hessian_operator.hpp"

namespace viscompm::linalg {

double massless_row_scale(const implicit::IncrementalPotential& potential, const parallel::Communicator& comm) {
  double mass = 0.0, count = 0.0;
  for (std::size_t i = 0; i < potential.layout().owned_count; ++i)
    if (potential.mass()[i] > 0.0) {
      mass += potential.mass()[i];
      count += 1.0;
    }
  const double total_count = comm.sum(count);
  return total_count > 0.0 ? comm.sum(mass) / total_count : 1.0;
}

namespace {
using row_map_view = crs_matrix_type::local_graph_device_type::row_map_type::non_const_type;
using entries_view = crs_matrix_type::local_graph_device_type::entries_type::non_const_type;
using values_view = crs_matrix_type::local_matrix_device_type::values_type;

class AssembledHessian : public HessianOperator {
 public:
  explicit AssembledHessian(const NodeSpace& space) : space_(space) {}

  void build_pattern() override;
  void update(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    if (matrix_.is_null() || space_.version() != graph_version_)
      throw std::logic_error("AssembledHessian: the graph was not built for the current node partition");
    fill(potential, v, project);
  }
  Teuchos::RCP<const operator_type> op() const override { return matrix_; }
  Teuchos::RCP<crs_matrix_type> matrix() const override { return matrix_; }
  Teuchos::RCP<const vector_type> diagonal() const override {
    auto d = Teuchos::rcp(new vector_type(matrix_->getRowMap()));
    matrix_->getLocalDiagCopy(*d);
    return d;
  }
  std::int64_t nonzeros() const override { return nonzeros_; }

 private:
  void fill(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project);
  void add_free_cell(const int* nodes, const implicit::ElementHessian& element, int owned, int K);
  void add_inertia(const implicit::IncrementalPotential& potential, int owned);

  const NodeSpace& space_;
  std::uint64_t graph_version_ = 0;
  std::int64_t nonzeros_ = 0;
  Teuchos::RCP<crs_matrix_type> matrix_;
  row_map_view row_offsets_;
  values_view values_;
  std::vector<int> pair_positions_;   // window position of stencil node b seen from stencil node a (K×K)
  std::vector<std::size_t> diagonal_;  // offset of node i's diagonal block in its first row
};

void AssembledHessian::build_pattern() {
  const auto& s = space_.impl();
  const parallel::NodePartition& partition = space_.partition();
  const std::size_t owned = partition.owned_count();
  // Dof rows from node rows: row 3i+σ holds the columns 3j+τ of every column node j of node i.
  row_offsets_ = row_map_view("viscompm Hessian row offsets", 3 * owned + 1);
  std::size_t entries = 0;
  for (std::size_t i = 0; i < owned; ++i) {
    const std::size_t columns = 3 * (partition.row_begin(i + 1) - partition.row_begin(i));
    for (int sigma = 0; sigma < 3; ++sigma) {
      row_offsets_(3 * i + sigma) = entries;
      entries += columns;
    }
  }
  row_offsets_(3 * owned) = entries;
  entries_view columns("viscompm Hessian columns", entries);
  const auto& row_columns = partition.row_columns();
  diagonal_.resize(owned);
  for (std::size_t i = 0; i < owned; ++i) {
    for (int sigma = 0; sigma < 3; ++sigma) {
      std::size_t at = row_offsets_(3 * i + sigma);
      for (std::size_t k = partition.row_begin(i); k < partition.row_begin(i + 1); ++k)
        for (int tau = 0; tau < 3; ++tau) columns(at++) = 3 * row_columns[k] + tau;
    }
    const int center = partition.window_size() / 2;
    diagonal_[i] = 3 * static_cast<std::size_t>(partition.window_slots(i)[center]);
  }
  values_ = values_view("viscompm Hessian values", entries);
  matrix_ = Teuchos::rcp(new crs_matrix_type(s.owned_dof_map, s.column_dof_map, row_offsets_, columns, values_));
  matrix_->expertStaticFillComplete(s.owned_dof_map, s.owned_dof_map, s.dof_import);
  nonzeros_ = space_.comm().sum(static_cast<std::int64_t>(entries));

  // Window position of stencil node b as seen from stencil node a.
  const int width = grid::stencil_width(partition.order());
  const int K = grid::stencil_size(partition.order());
  const int R = partition.window_radius(), W = 2 * R + 1;
  pair_positions_.resize(static_cast<std::size_t>(K) * K);
  for (int a = 0; a < K; ++a)
    for (int b = 0; b < K; ++b) {
      const int dx = b % width - a % width, dy = (b / width) % width - (a / width) % width,
                dz = b / (width * width) - a / (width * width);
      pair_positions_[a * K + b] = (dx + R) + W * ((dy + R) + W * (dz + R));
    }
  graph_version_ = space_.version();
}

void AssembledHessian::fill(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) {
  const grid::GridLayout& layout = potential.layout();
  const parallel::NodePartition& partition = space_.partition();
  const int owned = static_cast<int>(layout.owned_count);
  const int K = layout.nodes_per_cell();
  double* values = values_.data();
  std::fill(values, values + values_.extent(0), 0.0);

  // Adds block B to row node i (owned) at the column of stencil node b seen from stencil node a.
  auto add_block = [&](int i, int a, int b, const Mat3& B) {
    const std::size_t slot = 3 * static_cast<std::size_t>(partition.window_slots(i)[pair_positions_[a * K + b]]);
    for (int sigma = 0; sigma < 3; ++sigma) {
      double* row = values + row_offsets_(3 * i + sigma) + slot;
      row[0] += B(sigma, 0);
      row[1] += B(sigma, 1);
      row[2] += B(sigma, 2);
    }
  };
  potential.element_hessians(v, project, [&](std::size_t c, const implicit::ElementHessian& element) {
    const int* nodes = layout.nodes_of_cell(c);
    if (!potential.cell_is_free(c)) {
      // Constrained nodes in the stencil: the blocks through P_i B P_j.
      for (int a = 0; a < K; ++a)
        for (int b = a; b < K; ++b) {
          const bool row_a = nodes[a] < owned, row_b = nodes[b] < owned && b != a;
          if (!row_a && !row_b) continue;
          const Mat3 B = potential.constrained_block(element, c, a, b);
          if (row_a) add_block(nodes[a], a, b, B);
          if (row_b) add_block(nodes[b], b, a, B.transpose());
        }
      return;
    }
    add_free_cell(nodes, element, owned, K);
  });
  add_inertia(potential, owned);
}

// A cell whose stencil has no constrained node: the element's lanes read directly into the rows
// of a and of b.
void AssembledHessian::add_free_cell(const int* nodes, const implicit::ElementHessian& element, int owned, int K) {
  const parallel::NodePartition& partition = space_.partition();
  double* values = values_.data();
  for (int a = 0; a < K; ++a) {
    const int i = nodes[a];
    const bool row_a = i < owned;
    const double* e[3][3];
    for (int sigma = 0; sigma < 3; ++sigma)
      for (int tau = 0; tau < 3; ++tau) e[sigma][tau] = element.lanes(a, sigma, tau);
    double* rows_a[3] = {nullptr, nullptr, nullptr};
    const std::int16_t* slots_a = nullptr;
    if (row_a) {
      for (int sigma = 0; sigma < 3; ++sigma) rows_a[sigma] = values + row_offsets_(3 * i + sigma);
      slots_a = partition.window_slots(i);
    }
    const int* positions_a = pair_positions_.data() + a * K;
    // Diagonal block, symmetrised.
    if (row_a) {
      const std::size_t slot = 3 * static_cast<std::size_t>(slots_a[positions_a[a]]);
      for (int sigma = 0; sigma < 3; ++sigma)
        for (int tau = 0; tau < 3; ++tau) rows_a[sigma][slot + tau] += 0.5 * (e[sigma][tau][a] + e[tau][sigma][a]);
    }
    for (int b = a + 1; b < K; ++b) {
      const int j = nodes[b];
      if (row_a) {
        const std::size_t slot = 3 * static_cast<std::size_t>(slots_a[positions_a[b]]);
        for (int sigma = 0; sigma < 3; ++sigma) {
          double* row = rows_a[sigma] + slot;
          row[0] += e[sigma][0][b];
          row[1] += e[sigma][1][b];
          row[2] += e[sigma][2][b];
        }
      }
      if (j < owned) {
        const std::size_t slot = 3 * static_cast<std::size_t>(partition.window_slots(j)[pair_positions_[b * K + a]]);
        for (int tau = 0; tau < 3; ++tau) {
          double* row = values + row_offsets_(3 * j + tau) + slot;
          row[0] += e[0][tau][b];
          row[1] += e[1][tau][b];
          row[2] += e[2][tau][b];
        }
      }
    }
  }
}

void AssembledHessian::add_inertia(const implicit::IncrementalPotential& potential, int owned) {
  double* values = values_.data();
  // Inertia m_i on the diagonal; nodes without mass (the partition's padding) get identity rows
  // scaled like an average node, so that the matrix stays SPD and their dv is zero.
  const double scale = massless_row_scale(potential, space_.comm());
  for (int i = 0; i < owned; ++i) {
    const double m = potential.mass()[i];
    for (int sigma = 0; sigma < 3; ++sigma) values[row_offsets_(3 * i + sigma) + diagonal_[i] + sigma] += m > 0.0 ? m : scale;
  }
}
}  // namespace

std::unique_ptr<HessianOperator> make_assembled_hessian(const NodeSpace& space) {
  return std::make_unique<AssembledHessian>(space);
}

}  // namespace viscompm::linalg
