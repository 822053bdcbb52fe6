#include "viscompm/linalg/matrix_market.hpp"

#include <MatrixMarket_Tpetra.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "krylov.hpp"
#include "preconditioner.hpp"
#include "matrix_market_io.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/parallel/decomposition.hpp"

namespace viscompm::linalg {

void write_contiguous_matrix_market(const crs_matrix_type& A, const multivector_type& b,
                                    const multivector_type& coordinates, const std::string& prefix) {
  const auto comm = A.getRowMap()->getComm();
  const auto rows = A.getRowMap()->getNodeNumElements();
  const auto contiguous = Teuchos::rcp(new map_type(A.getRowMap()->getGlobalNumElements(), rows, 0, comm));
  // New ids of the owned rows, then of every column (through the matrix's import).
  Tpetra::Vector<global_ordinal_type, local_ordinal_type, global_ordinal_type, node_type> owned_ids(A.getRowMap()),
      column_ids(A.getColMap());
  {
    auto v = owned_ids.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t r = 0; r < rows; ++r) v(r, 0) = contiguous->getGlobalElement(static_cast<local_ordinal_type>(r));
  }
  // (The graph has no importer when every column is local.)
  Teuchos::RCP<const import_type> importer = A.getGraph()->getImporter();
  if (importer.is_null()) importer = Teuchos::rcp(new import_type(A.getDomainMap(), A.getColMap()));
  column_ids.doImport(owned_ids, *importer, Tpetra::INSERT);
  auto renumbered = Teuchos::rcp(new crs_matrix_type(contiguous, A.getGlobalMaxNumRowEntries()));
  {
    auto ids = column_ids.getLocalViewHost(Tpetra::Access::ReadOnly);
    std::vector<global_ordinal_type> columns;
    for (std::size_t r = 0; r < rows; ++r) {
      crs_matrix_type::local_inds_host_view_type cols;
      crs_matrix_type::values_host_view_type vals;
      A.getLocalRowView(static_cast<local_ordinal_type>(r), cols, vals);
      columns.resize(cols.extent(0));
      for (std::size_t k = 0; k < cols.extent(0); ++k) columns[k] = ids(cols(k), 0);
      renumbered->insertGlobalValues(contiguous->getGlobalElement(static_cast<local_ordinal_type>(r)),
                                     static_cast<local_ordinal_type>(columns.size()), vals.data(), columns.data());
    }
  }
  renumbered->fillComplete();
  auto rhs = Teuchos::rcp(new multivector_type(contiguous, 1));
  {
    auto out = rhs->getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto in = b.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t r = 0; r < rows; ++r) out(r, 0) = in(r, 0);
  }
  using writer = Tpetra::MatrixMarket::Writer<crs_matrix_type>;
  writer::writeSparseFile(prefix + ".mtx", renumbered, "viscompm Newton matrix", "H = M + dt^2 Hess(Phi)");
  writer::writeDenseFile(prefix + "_rhs.mtx", rhs, "viscompm Newton right-hand side", "-grad E");
  // Node k of the renumbering owns rows 3k..3k+2: the owned node map is contiguous in that order.
  auto xyz = Teuchos::rcp(new multivector_type(
      Teuchos::rcp(new map_type(coordinates.getMap()->getGlobalNumElements(), coordinates.getLocalLength(), 0, comm)), 3));
  {
    auto out = xyz->getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto in = coordinates.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t r = 0; r < coordinates.getLocalLength(); ++r)
      for (int d = 0; d < 3; ++d) out(r, d) = in(r, d);
  }
  writer::writeDenseFile(prefix + "_coordinates.mtx", xyz, "viscompm node coordinates", "x y z per node");
}

std::string rhs_file_for(const std::string& matrix_file) {
  const std::filesystem::path p(matrix_file);
  return (p.parent_path() / (p.stem().string() + "_rhs" + p.extension().string())).string();
}

std::string coordinates_file_for(const std::string& matrix_file) {
  const std::filesystem::path p(matrix_file);
  return (p.parent_path() / (p.stem().string() + "_coordinates" + p.extension().string())).string();
}

namespace {
// A fixed matrix behind the HessianOperator interface the preconditioners take.
class FixedMatrix : public HessianOperator {
 public:
  explicit FixedMatrix(Teuchos::RCP<crs_matrix_type> A) : A_(std::move(A)) {}
  void build_pattern() override {}
  void update(const implicit::IncrementalPotential&, const NodeVectorField&, bool) override {}
  Teuchos::RCP<const operator_type> op() const override { return A_; }
  Teuchos::RCP<crs_matrix_type> matrix() const override { return A_; }
  Teuchos::RCP<const vector_type> diagonal() const override {
    auto d = Teuchos::rcp(new vector_type(A_->getRowMap()));
    A_->getLocalDiagCopy(*d);
    return d;
  }
  std::int64_t nonzeros() const override { return static_cast<std::int64_t>(A_->getGlobalNumEntries()); }

 private:
  Teuchos::RCP<crs_matrix_type> A_;
};
}  // namespace

namespace {
// The lattice behind node coordinates (a dump of an MPM grid): spacing = the smallest distance
// between distinct coordinates, origin = the smallest coordinate, per axis; coarse levels of a
// geometric hierarchy are owned in blocks of that lattice.
std::shared_ptr<const SystemGrid> grid_from_coordinates(const multivector_type& coordinates,
                                                        const parallel::Communicator& comm) {
  auto xyz = coordinates.getLocalViewHost(Tpetra::Access::ReadOnly);
  const std::size_t n = coordinates.getLocalLength();
  Vec3 lowest = Vec3::Constant(std::numeric_limits<double>::infinity());
  double spacing = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    std::vector<double> values(n);
    for (std::size_t i = 0; i < n; ++i) values[i] = xyz(i, d);
    std::sort(values.begin(), values.end());
    for (std::size_t i = 0; i < n; ++i) {
      lowest[d] = std::min(lowest[d], values[i]);
      if (i > 0 && values[i] - values[i - 1] > 1e-9 * std::abs(values[i])) spacing = std::min(spacing, values[i] - values[i - 1]);
    }
    lowest[d] = comm.min(lowest[d]);
  }
  spacing = comm.min(spacing);
  if (!std::isfinite(spacing)) throw InputError("fewer than two distinct node positions");
  auto grid = std::make_shared<SystemGrid>();
  Int3 highest = Int3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Int3 ijk(static_cast<int>(std::lround((xyz(i, 0) - lowest.x()) / spacing)),
                   static_cast<int>(std::lround((xyz(i, 1) - lowest.y()) / spacing)),
                   static_cast<int>(std::lround((xyz(i, 2) - lowest.z()) / spacing)));
    grid->owned_nodes.push_back(ijk);
    highest = highest.cwiseMax(ijk);
  }
  for (int d = 0; d < 3; ++d) grid->dimensions[d] = static_cast<int>(comm.max(std::int64_t(highest[d]))) + 1;
  grid::GridGeometry lattice;
  lattice.cells = grid->dimensions - Int3::Ones();
  auto blocks = std::make_shared<parallel::BlockDecomposition>(lattice, comm.size());
  grid->owner = [blocks](const Int3& ijk) { return blocks->owner_of_node(ijk); };
  return grid;
}
}  // namespace

namespace {
// Checks what Tpetra's reader takes on trust in a coordinate file: that it holds as many entries
// as its size line announces (a cut file was read as a smaller matrix) and that every entry is a
// pair of indices in range with a finite value. Empty if sound, else the reason (rank 0 reads).
std::string coordinate_file_problem(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return "empty file";
  try {
    const Teuchos::MatrixMarket::Banner banner(line);
    if (banner.matrixType() != "coordinate" || banner.dataType() != "real")
      return "not a real coordinate matrix (" + banner.matrixType() + " " + banner.dataType() + ")";
  } catch (const std::exception&) {
    return "no MatrixMarket banner (%%MatrixMarket matrix coordinate real ...)";
  }
  while (std::getline(in, line) && (line.empty() || line[0] == '%')) {
  }
  long long rows = -1, columns = -1, entries = -1;
  if (std::sscanf(line.c_str(), "%lld %lld %lld", &rows, &columns, &entries) != 3 || rows < 0 || columns < 0 || entries < 0)
    return "no size line (rows columns entries)";
  long long found = 0;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '%') continue;
    long long i = 0, j = 0;
    double value = 0.0;
    int used = 0;
    if (std::sscanf(line.c_str(), "%lld %lld %lf%n", &i, &j, &value, &used) != 3 ||
        line.find_first_not_of(" \t\r", used) != std::string::npos)
      return "entry " + std::to_string(found + 1) + " ('" + line.substr(0, 60) + "') is not 'row column value'";
    if (i < 1 || i > rows || j < 1 || j > columns)
      return "entry " + std::to_string(found + 1) + " (" + std::to_string(i) + ", " + std::to_string(j) +
             ") lies outside the " + std::to_string(rows) + " x " + std::to_string(columns) + " matrix";
    if (!std::isfinite(value)) return "entry " + std::to_string(found + 1) + " is not a finite number";
    if (++found > entries) break;
  }
  if (found != entries)
    return "its size line announces " + std::to_string(entries) + " entries, the file holds " +
           (found > entries ? "more" : "only " + std::to_string(found)) + " (cut short or corrupted?)";
  return {};
}

// Rank 0's answer, on every rank.
std::string broadcast(const std::string& text, const parallel::Communicator& comm) {
  int size = static_cast<int>(text.size());
  MPI_Bcast(&size, 1, MPI_INT, 0, comm.comm());
  std::string received = comm.is_root() ? text : std::string(size, ' ');
  MPI_Bcast(received.data(), size, MPI_CHAR, 0, comm.comm());
  return received;
}

// The last line of a Trilinos exception (its reason; the lines before name the source).
std::string last_line(const std::string& message) {
  std::istringstream in(message);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t-") != std::string::npos) last = line;
  return last.substr(0, 200);
}

// A dense MatrixMarket file (right-hand side, coordinates) of `map`'s rows: InputError naming the
// file when Tpetra cannot read it (cut short, a word for a number, the wrong size) or a value is
// not finite.
Teuchos::RCP<multivector_type> read_dense(const std::string& file, const Teuchos::RCP<const Teuchos::Comm<int>>& comm,
                                          const Teuchos::RCP<const map_type>& map, const std::string& what) {
  using reader = Tpetra::MatrixMarket::Reader<crs_matrix_type>;
  Teuchos::RCP<multivector_type> values;
  try {
    Teuchos::RCP<const map_type> rows = map;  // the reader takes it by reference
    values = reader::readDenseFile(file, comm, rows);
  } catch (const std::exception& e) {
    throw InputError(file + ": not a readable MatrixMarket array of " + what + " (" + last_line(e.what()) + ")");
  }
  bool finite = true;
  auto host = values->getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < host.extent(0); ++i)
    for (std::size_t k = 0; k < host.extent(1); ++k) finite &= std::isfinite(host(i, k));
  int all_finite = finite ? 1 : 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MIN, 1, &all_finite, &all_finite);
  if (!all_finite) throw InputError(file + ": a value of the " + what + " is not a finite number");
  return values;
}
}  // namespace

struct MatrixMarketProblem::Impl {
  Teuchos::RCP<crs_matrix_type> A;
  Teuchos::RCP<multivector_type> b;
  NearNullspace modes;
};

MatrixMarketProblem::MatrixMarketProblem(const std::string& matrix_file, const parallel::Communicator& comm)
    : impl_(std::make_unique<Impl>()) {
  if (comm.any(!std::ifstream(matrix_file).good())) throw InputError(matrix_file + ": cannot open file");
  const std::string problem = broadcast(comm.is_root() ? coordinate_file_problem(matrix_file) : std::string(), comm);
  if (!problem.empty()) throw InputError(matrix_file + ": not a readable MatrixMarket matrix: " + problem);
  const auto tcomm = Teuchos::rcp(new Teuchos::MpiComm<int>(comm.comm()));
  using reader = Tpetra::MatrixMarket::Reader<crs_matrix_type>;
  Teuchos::RCP<crs_matrix_type> A;
  try {
    A = reader::readSparseFile(matrix_file, tcomm);
  } catch (const std::exception& e) {
    throw InputError(matrix_file + ": not a readable MatrixMarket matrix (" + last_line(e.what()) + ")");
  }
  if (A->getGlobalNumRows() != A->getGlobalNumCols())
    throw InputError(matrix_file + ": the matrix is not square (" + std::to_string(A->getGlobalNumRows()) + " x " +
                     std::to_string(A->getGlobalNumCols()) + ")");
  // With coordinates: rows by node, so that the 3 dofs of a node share a rank (MueLu's blocks).
  const std::string coordinates_file = coordinates_file_for(matrix_file);
  if (comm.any(std::ifstream(coordinates_file).good())) {
    const auto rows = A->getGlobalNumRows();
    if (rows % 3 != 0) throw InputError(coordinates_file + ": the matrix has " + std::to_string(rows) +
                                        " rows, not 3 per node");
    Teuchos::RCP<const map_type> node_map = Teuchos::rcp(new map_type(rows / 3, 0, tcomm));
    const Teuchos::RCP<const map_type> dof_map =
        Teuchos::rcp(new map_type(rows, 3 * node_map->getNodeNumElements(), 0, tcomm));
    const import_type to_nodes(A->getRowMap(), dof_map);
    A = Tpetra::importAndFillCompleteCrsMatrix<crs_matrix_type>(A, to_nodes, dof_map, dof_map);
    impl_->modes.coordinates = read_dense(coordinates_file, tcomm, node_map, "node coordinates");
    if (impl_->modes.coordinates->getNumVectors() != 3)
      throw InputError(coordinates_file + ": expected 3 columns (x, y, z)");
    impl_->modes.rigid_body_modes = rigid_body_modes(*impl_->modes.coordinates, dof_map);
    try {
      impl_->modes.grid = grid_from_coordinates(*impl_->modes.coordinates, comm);
    } catch (const InputError& e) {
      throw InputError(coordinates_file + ": " + e.what());
    }
  }
  impl_->A = A;
  impl_->b = Teuchos::rcp(new multivector_type(A->getRangeMap(), 1));
  const std::string rhs_file = rhs_file_for(matrix_file);
  if (comm.any(std::ifstream(rhs_file).good())) {
    const auto b = read_dense(rhs_file, tcomm, A->getRangeMap(), "right-hand side");
    if (b->getNumVectors() != 1) throw InputError(rhs_file + ": expected 1 column (the right-hand side)");
    impl_->b->assign(*b);
  } else {
    impl_->b->putScalar(1.0);
  }
}

MatrixMarketProblem::~MatrixMarketProblem() = default;

std::int64_t MatrixMarketProblem::rows() const { return static_cast<std::int64_t>(impl_->A->getGlobalNumRows()); }
std::int64_t MatrixMarketProblem::nonzeros() const {
  return static_cast<std::int64_t>(impl_->A->getGlobalNumEntries());
}
bool MatrixMarketProblem::has_coordinates() const { return !impl_->modes.coordinates.is_null(); }

MatrixMarketSolve MatrixMarketProblem::solve(const SolverConfiguration& config) const {
  if (config.impl().settings.operator_form == OperatorForm::matrix_free)
    throw InputError(config.origin() + ": a matrix-free configuration cannot solve a MatrixMarket system");
  const auto& A = impl_->A;
  config.check_rank_count(A->getComm()->getSize());
  multivector_type x(A->getDomainMap(), 1), b(*impl_->b, Teuchos::Copy);
  FixedMatrix H(A);
  auto preconditioner = make_preconditioner(config);
  const auto start = std::chrono::steady_clock::now();
  preconditioner->setup(H, true, impl_->modes);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  KrylovSolver krylov(config);
  MatrixMarketSolve result;
  result.report = krylov.solve(A, preconditioner->op(), x, b);
  result.report.setup_seconds = setup;
  const auto apply_start = std::chrono::steady_clock::now();
  for (int k = 0; k < 5; ++k) A->apply(x, b);
  result.apply_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - apply_start).count() / 5;
  if (const auto M = preconditioner->op(); !M.is_null()) {
    const auto preconditioner_start = std::chrono::steady_clock::now();
    for (int k = 0; k < 5; ++k) M->apply(b, x);
    result.preconditioner_apply_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - preconditioner_start).count() / 5;
  }
  return result;
}

}  // namespace viscompm::linalg
