#include "line_smoother.hpp"

#include <cmath>
#include <stdexcept>

// LAPACK's banded Cholesky (Teuchos::LAPACK has no PBTRF/PBTRS).
extern "C" {
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab, const int* ldab,
             double* b, const int* ldb, int* info);
}

namespace viscompm::linalg {

template <class Visit>
void LineSmoother::for_each_line_entry(const crs_matrix_type& A, Visit&& visit) {
  const std::size_t n = A.getNodeNumRows();
  for (std::size_t r = 0; r < n; ++r) {
    crs_matrix_type::local_inds_host_view_type cols;
    crs_matrix_type::values_host_view_type vals;
    A.getLocalRowView(static_cast<local_ordinal_type>(r), cols, vals);
    const std::size_t node = r / 3;
    const int sigma = static_cast<int>(r % 3);
    for (int axis = 0; axis < 3; ++axis) {
      const int l = line_of_[3 * node + axis];
      if (l < 0) continue;
      const int i = 3 * position_of_[3 * node + axis] + sigma;
      for (std::size_t k = 0; k < cols.extent(0); ++k) {
        const int row = column_row_[cols(k)];
        if (row < 0) continue;
        const std::size_t other = static_cast<std::size_t>(row) / 3;
        if (line_of_[3 * other + axis] != l) continue;
        const int j = 3 * position_of_[3 * other + axis] + row % 3;
        if (i >= j) visit(factors_[l], i, j, vals(k));
      }
    }
  }
}

void LineSmoother::index_lines(const crs_matrix_type& A) {
  const auto& rows = *A.getRowMap();
  const auto& columns = *A.getColMap();
  const std::size_t n = A.getNodeNumRows();
  // Local column → local row (−1 for a ghost column).
  column_row_.assign(columns.getNodeNumElements(), -1);
  for (std::size_t c = 0; c < column_row_.size(); ++c)
    column_row_[c] = rows.getLocalElement(columns.getGlobalElement(static_cast<local_ordinal_type>(c)));
  // Each node's position on its line of each axis (lines come axis by axis, one per node each).
  const std::size_t nodes = n / 3;
  line_of_.assign(3 * nodes, -1);
  position_of_.assign(3 * nodes, -1);
  {
    std::vector<int> seen(nodes, 0);
    for (std::size_t l = 0; l < lines_.size(); ++l)
      for (std::size_t k = 0; k < lines_[l].size(); ++k) {
        const std::size_t node = lines_[l][k];
        const int axis = seen[node]++;
        if (axis > 2) throw std::logic_error("LineSmoother: a node on more than three lines");
        line_of_[3 * node + axis] = static_cast<int>(l);
        position_of_[3 * node + axis] = static_cast<int>(k);
      }
  }
  // Each line's band: the farthest entry of A's graph below the diagonal of its block.
  factors_.assign(lines_.size(), BandFactor{});
  for (std::size_t l = 0; l < lines_.size(); ++l) factors_[l].rows = static_cast<int>(3 * lines_[l].size());
  for_each_line_entry(A, [&](BandFactor& f, int i, int j, double) { f.graph_bandwidth = std::max(f.graph_bandwidth, i - j); });
  indexed_graph_ = A.getCrsGraph().get();
}

void LineSmoother::compute(const crs_matrix_type& A, const operator_type& apply_A, double line_damping) {
  if (indexed_graph_ != A.getCrsGraph().get()) index_lines(A);
  for (BandFactor& f : factors_) {
    f.bandwidth = f.graph_bandwidth;
    f.band.assign(static_cast<std::size_t>(f.bandwidth + 1) * f.rows, 0.0);
  }
  // The lower band of each line's block, column-major: entry (i, j), i ≥ j, at j (bandwidth + 1) + i − j.
  for_each_line_entry(A, [](BandFactor& f, int i, int j, double value) { f.band[j * (f.bandwidth + 1) + (i - j)] = value; });
  std::vector<double> diagonal;
  for (BandFactor& f : factors_) {
    const int ld = f.bandwidth + 1;
    diagonal.resize(f.rows);
    for (int j = 0; j < f.rows; ++j) diagonal[j] = f.band[static_cast<std::size_t>(j) * ld];
    int info = 0;
    dpbtrf_("L", &f.rows, &f.bandwidth, f.band.data(), &ld, &info);
    if (info != 0) {
      // No Cholesky factor: H assembled unprojected (Newton's first attempt under adaptive
      // projection) is indefinite on this line. The smoother must stay SPD for CG, so the line is
      // smoothed by |diag H| (Jacobi); whether CG can use H itself is Newton's to find out.
      double largest = 0.0;
      for (const double d : diagonal) largest = std::max(largest, std::abs(d));
      f.bandwidth = 0;
      f.band.resize(static_cast<std::size_t>(f.rows));
      for (int j = 0; j < f.rows; ++j) {
        const double d = std::abs(diagonal[j]);
        f.band[j] = std::sqrt(d > 1e-12 * largest ? d : (largest > 0.0 ? largest : 1.0));
      }
    }
  }
  // The damping: Line damping over λmax(S A), by power iterations.
  largest_eigenvalue_ = smoothed_largest_eigenvalue(
      apply_A, [this](const vector_type& in, vector_type& out) { apply_undamped(in, out); }, eigenvector_);
  damping_ = line_damping / largest_eigenvalue_;
}

double smoothed_largest_eigenvalue(const operator_type& A, const std::function<void(const vector_type&, vector_type&)>& smooth,
                                   Teuchos::RCP<vector_type>& eigenvector) {
  int iterations = 5;
  if (eigenvector.is_null() || eigenvector->getLocalLength() != A.getDomainMap()->getNodeNumElements()) {
    eigenvector = Teuchos::rcp(new vector_type(A.getDomainMap()));
    auto view = eigenvector->getLocalViewHost(Tpetra::Access::OverwriteAll);
    const auto& map = *A.getDomainMap();
    for (std::size_t i = 0; i < view.extent(0); ++i)
      view(i, 0) = 1.0 + 0.5 * std::sin(1.7 * static_cast<double>(map.getGlobalElement(static_cast<local_ordinal_type>(i))));
    iterations = 12;
  }
  vector_type& x = *eigenvector;
  vector_type y(A.getRangeMap());
  double lambda = 1.0;
  for (int k = 0; k < iterations; ++k) {
    x.scale(1.0 / x.norm2());
    A.apply(x, y);
    smooth(y, x);
    lambda = x.norm2();
  }
  return lambda;
}

template <class In, class Out>
void LineSmoother::solve_blocks(const In& x, Out& y, std::size_t j) const {
  std::vector<double> b;
  const int one = 1;
  for (std::size_t l = 0; l < lines_.size(); ++l) {
    const auto& line = lines_[l];
    const BandFactor& f = factors_[l];
    b.resize(3 * line.size());
    for (std::size_t k = 0; k < line.size(); ++k)
      for (int d = 0; d < 3; ++d) b[3 * k + d] = x(3 * line[k] + d, j);
    const int ld = f.bandwidth + 1;
    int info = 0;
    dpbtrs_("L", &f.rows, &f.bandwidth, &one, f.band.data(), &ld, b.data(), &f.rows, &info);
    for (std::size_t k = 0; k < line.size(); ++k)
      for (int d = 0; d < 3; ++d) y(3 * line[k] + d, j) += b[3 * k + d];
  }
}

void LineSmoother::apply_scaled(const multivector_type& x, multivector_type& y, double scale) const {
  auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
  auto yv = y.getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (std::size_t j = 0; j < xv.extent(1); ++j) {
    for (std::size_t i = 0; i < xv.extent(0); ++i) yv(i, j) = 0.0;
    solve_blocks(xv, yv, j);
    if (scale != 1.0)
      for (std::size_t i = 0; i < xv.extent(0); ++i) yv(i, j) *= scale;
  }
}

}  // namespace viscompm::linalg
