// The preconditioners: none, Jacobi, Ifpack2 (any Ifpack2::Factory type) and MueLu: algebraic
// (aggregation, with coordinates and the rigid-body near-nullspace in its "user data") or on
// geometric prolongators between the grids Δx, 2Δx, 4Δx, ... (parallel/grid_hierarchy) that MueLu
// takes as each level's P, forming the Galerkin products and smoothers itself.
#include <Ifpack2_Factory.hpp>
#include <MueLu_CreateTpetraPreconditioner.hpp>
#include <MueLu_HierarchyUtils.hpp>
#include <MueLu_Ifpack2Smoother.hpp>
#include <MueLu_TrilinosSmoother.hpp>
#include <MueLu_ParameterListInterpreter.hpp>

#include "preconditioner.hpp"

#include "lean_cycle.hpp"
#include "line_smoother.hpp"

#include <Ifpack2_BlockRelaxation.hpp>
#include <Ifpack2_Chebyshev.hpp>
#include <iostream>
#include <streambuf>
#include <Teuchos_ScalarTraits.hpp>

#include "viscompm/grid/node_lines.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/parallel/grid_hierarchy.hpp"

namespace viscompm::linalg {

Teuchos::RCP<multivector_type> rigid_body_modes(const multivector_type& coordinates,
                                                const Teuchos::RCP<const map_type>& dof_map) {
  auto modes = Teuchos::rcp(new multivector_type(dof_map, 6));
  auto xyz = coordinates.getLocalViewHost(Tpetra::Access::ReadOnly);
  auto rbm = modes->getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (std::size_t i = 0; i < coordinates.getLocalLength(); ++i) {
    const double x = xyz(i, 0), y = xyz(i, 1), z = xyz(i, 2);
    for (int d = 0; d < 3; ++d) {
      for (int m = 0; m < 6; ++m) rbm(3 * i + d, m) = 0.0;
      rbm(3 * i + d, d) = 1.0;  // translations
    }
    rbm(3 * i + 1, 3) = -z; rbm(3 * i + 2, 3) = y;
    rbm(3 * i + 0, 4) = z;  rbm(3 * i + 2, 4) = -x;
    rbm(3 * i + 0, 5) = -y; rbm(3 * i + 1, 5) = x;
  }
  return modes;
}

namespace {
using parts_type = Teuchos::Array<Teuchos::ArrayRCP<local_ordinal_type>>;

// Grid index of node `id` (x fastest) on a grid of `dims` nodes.
Int3 node_index(std::int64_t id, const Int3& dims) {
  const std::int64_t nx = dims.x(), ny = dims.y();
  return Int3(static_cast<int>(id % nx), static_cast<int>((id / nx) % ny), static_cast<int>(id / (nx * ny)));
}

// The runs of owned grid nodes along each axis as blocks of dofs (3 per node, consecutive).
parts_type grid_line_parts(const SystemGrid& grid, int max_nodes) {
  parts_type parts;
  for (const auto& line : grid::node_lines(grid.owned_nodes, max_nodes)) {
    Teuchos::ArrayRCP<local_ordinal_type> dofs(3 * line.size());
    for (std::size_t k = 0; k < line.size(); ++k)
      for (int d = 0; d < 3; ++d) dofs[3 * k + d] = static_cast<local_ordinal_type>(3 * line[k] + d);
    parts.push_back(dofs);
  }
  return parts;
}

// Smoother blocks = grid lines: a block-relaxation smoother's blocks from the grid, and its
// damping from the matrix it smooths.
class GridLines {
 public:
  /// The smoother's Ifpack2 list: the configured one with the blocks of `grid`.
  const Teuchos::ParameterList& prepare(const Teuchos::ParameterList& configured, const SystemGrid& grid, int max_nodes) {
    list_ = configured;
    list_.set("partitioner: parts", grid_line_parts(grid, max_nodes));
    eigenvector_ = Teuchos::null;
    return list_;
  }

  const Teuchos::ParameterList& list() const { return list_; }

  /// Additive (Jacobi) blocks need a damping below 2/λmax(S A), S one undamped sweep of block
  /// solves: `smoother` (set up on A with prepare()'s list) gets Line damping / λmax, λmax by power
  /// iterations that start from the last estimate's vector while the blocks stay (the same start
  /// on any rank count at first). Gauss-Seidel over the blocks needs none. Ifpack2 replaces its
  /// whole list on setParameters: every call passes the complete one.
  void set_damping(ifpack2_preconditioner_type& smoother, const crs_matrix_type& A, const SolverSettings& settings) {
    if (settings.line_combination != BlockCombination::jacobi) return;
    Teuchos::ParameterList one_sweep = list_;
    one_sweep.set("relaxation: damping factor", 1.0);
    one_sweep.set("relaxation: sweeps", 1);
    one_sweep.set("relaxation: zero starting solution", true);
    smoother.setParameters(one_sweep);
    const double lambda = smoothed_largest_eigenvalue(
        A, [&smoother](const vector_type& in, vector_type& out) { smoother.apply(in, out); }, eigenvector_);
    Teuchos::ParameterList damped = list_;
    damped.set("relaxation: damping factor", settings.line_damping / lambda);
    smoother.setParameters(damped);
  }

 private:
  Teuchos::ParameterList list_;            // the smoother's complete Ifpack2 list
  Teuchos::RCP<vector_type> eigenvector_;  // of the last estimate, for these blocks
};

// MueLu 13.2 prints a block-relaxation smoother's parameter list to std::cout whenever it sets one
// up (MueLu_Ifpack2Smoother_def.hpp, SetupBlockRelaxation: an unconditional print()); the
// hierarchy's set-up runs with std::cout silenced (doc/trilinos.md).
class SilencedStdout {
 public:
  SilencedStdout() : saved_(std::cout.rdbuf(&null_)) {}
  ~SilencedStdout() { std::cout.rdbuf(saved_); }
  SilencedStdout(const SilencedStdout&) = delete;
  SilencedStdout& operator=(const SilencedStdout&) = delete;

 private:
  struct NullBuffer : std::streambuf {
    int overflow(int c) override { return traits_type::not_eof(c); }
  } null_;
  std::streambuf* saved_;
};

class NoPreconditioner : public Preconditioner {
 public:
  void setup(const HessianOperator&, bool, const NearNullspace&) override {}
  Teuchos::RCP<operator_type> op() const override { return Teuchos::null; }
};

// Jacobi from the exact diagonal of H, assembled or matrix-free (the paper's preconditioner).
class JacobiPreconditioner : public Preconditioner {
 public:
  void setup(const HessianOperator& H, bool, const NearNullspace&) override {
    auto inverse = Teuchos::rcp(new vector_type(*H.diagonal(), Teuchos::Copy));
    inverse->reciprocal(*inverse);
    op_ = Teuchos::rcp(new InverseDiagonal(inverse));
  }
  Teuchos::RCP<operator_type> op() const override { return op_; }

 private:
  class InverseDiagonal : public operator_type {
   public:
    explicit InverseDiagonal(Teuchos::RCP<vector_type> d) : d_(std::move(d)) {}
    Teuchos::RCP<const map_type> getDomainMap() const override { return d_->getMap(); }
    Teuchos::RCP<const map_type> getRangeMap() const override { return d_->getMap(); }
    void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp, scalar_type alpha,
               scalar_type beta) const override {
      Y.elementWiseMultiply(alpha, *d_, X, beta);  // Y = α D⁻¹ X + β Y
    }

   private:
    Teuchos::RCP<vector_type> d_;
  };
  Teuchos::RCP<operator_type> op_;
};

// The grid a grid-line smoother needs (a scene's, or a MatrixMarket dump's with coordinates).
const SystemGrid* grid_of(const NearNullspace& modes) {
  if (!modes.grid) throw InputError("Smoother blocks = grid lines need the grid of the system (a scene, or a "
                                    "MatrixMarket dump with node coordinates)");
  return modes.grid.get();
}

class Ifpack2Preconditioner : public Preconditioner {
 public:
  explicit Ifpack2Preconditioner(const SolverConfiguration& config) : config_(config) {}
  void setup(const HessianOperator& H, bool pattern_changed, const NearNullspace& modes) override {
    const Teuchos::RCP<crs_matrix_type> A = H.matrix();
    const SolverSettings& settings = config_.impl().settings;
    const bool grid_lines = settings.smoother_blocks == SmootherBlocks::grid_lines;
    if (pattern_changed || prec_.is_null()) {
      prec_ = Ifpack2::Factory::create<row_matrix_type>(settings.ifpack2_type, A);
      if (prec_.is_null())
        throw parameter_error(config_.origin(), "Ifpack2 type", "unknown Ifpack2 preconditioner '" +
                         settings.ifpack2_type + "'");
      Teuchos::ParameterList params = *config_.impl().preconditioner_parameters;
      // 3×3 point-block relaxation: one block per node (a node's three dofs are consecutive).
      const bool block_relaxation = settings.ifpack2_kind == Ifpack2Kind::block_relaxation;
      if (block_relaxation && !grid_lines && !params.isParameter("partitioner: local parts"))
        params.set("partitioner: local parts", static_cast<local_ordinal_type>(A->getNodeNumRows() / 3));
      prec_->setParameters(grid_lines ? lines_.prepare(params, *grid_of(modes), settings.line_length) : params);
      prec_->initialize();
    } else if (settings.ifpack2_kind == Ifpack2Kind::block_relaxation) {
      // Ifpack2 13.2's block containers copy only the nonzero entries of a block when they are
      // computed again, over the factors of the last values: initialize() zeroes them first.
      prec_->initialize();
    }
    prec_->compute();  // new values, same pattern
    if (grid_lines) lines_.set_damping(*prec_, *A, settings);
  }
  Teuchos::RCP<operator_type> op() const override { return prec_; }

 private:
  SolverConfiguration config_;
  Teuchos::RCP<ifpack2_preconditioner_type> prec_;
  GridLines lines_;
};

// P of one coarse level: rows = the finer level's owned dofs, columns = this level's owned and
// ghost dofs; weight × I₃ per (fine node, coarse node). Built from local arrays.
Teuchos::RCP<crs_matrix_type> make_prolongator(const parallel::CoarseLevel& c, const Teuchos::RCP<const map_type>& fine_dofs,
                                               Teuchos::RCP<const map_type>& coarse_dofs) {
  using row_map_view = crs_matrix_type::local_graph_device_type::row_map_type::non_const_type;
  using entries_view = crs_matrix_type::local_graph_device_type::entries_type::non_const_type;
  using values_view = crs_matrix_type::local_matrix_device_type::values_type;
  const auto comm = fine_dofs->getComm();
  coarse_dofs = Teuchos::rcp(new map_type(3 * c.global_count, 3 * c.owned_count, 0, comm));
  std::vector<global_ordinal_type> column_gids(3 * c.nodes.size());
  for (std::size_t k = 0; k < c.nodes.size(); ++k)
    for (int d = 0; d < 3; ++d) column_gids[3 * k + d] = 3 * c.system_ids[k] + d;
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  const Teuchos::RCP<const map_type> columns =
      Teuchos::rcp(new map_type(invalid, Teuchos::ArrayView<const global_ordinal_type>(column_gids), 0, comm));
  const std::size_t fine_nodes = c.row_begin.size() - 1;
  row_map_view offsets("P offsets", 3 * fine_nodes + 1);
  entries_view indices("P columns", 3 * c.columns.size());
  values_view values("P values", 3 * c.columns.size());
  std::size_t at = 0;
  for (std::size_t i = 0; i < fine_nodes; ++i)
    for (int d = 0; d < 3; ++d) {
      offsets(3 * i + d) = at;
      for (std::size_t k = c.row_begin[i]; k < c.row_begin[i + 1]; ++k, ++at) {
        indices(at) = 3 * c.columns[k] + d;
        values(at) = c.weights[k];
      }
    }
  offsets(3 * fine_nodes) = at;
  Teuchos::Array<int> owners(3 * c.ghost_owners.size());
  for (std::size_t g = 0; g < c.ghost_owners.size(); ++g)
    for (int d = 0; d < 3; ++d) owners[3 * g + d] = c.ghost_owners[g];
  const auto importer = Teuchos::rcp(new import_type(coarse_dofs, columns, owners));
  auto P = Teuchos::rcp(new crs_matrix_type(fine_dofs, columns, offsets, indices, values));
  P->expertStaticFillComplete(coarse_dofs, fine_dofs, importer);
  return P;
}

// While it lives, the entries of A that are exactly zero hold a tiny positive value instead
// (far below rounding of any real entry), so that a product formed meanwhile keeps them in its
// pattern; they are zero again afterwards.
class StructuralZeros {
 public:
  explicit StructuralZeros(crs_matrix_type& A) : values_(A.getLocalMatrixDevice().values) {
    for (std::size_t k = 0; k < values_.extent(0); ++k)
      if (values_(k) == 0.0) {
        values_(k) = tiny;
        filled_.push_back(k);
      }
  }
  ~StructuralZeros() {
    for (const std::size_t k : filled_) values_(k) = 0.0;
  }
  StructuralZeros(const StructuralZeros&) = delete;
  StructuralZeros& operator=(const StructuralZeros&) = delete;

 private:
  static constexpr double tiny = 1e-200;
  crs_matrix_type::local_matrix_device_type::values_type values_;
  std::vector<std::size_t> filled_;
};

class MueLuPreconditioner : public Preconditioner {
 public:
  explicit MueLuPreconditioner(const SolverConfiguration& config) : config_(config) {}
  // New values on the same pattern refresh what depends on values and keep what does not: a
  // geometric hierarchy keeps its prolongators and the patterns of its Galerkin products (MueLu's
  // "RP" reuse: only their values are recomputed) and rebuilds the smoothers and the coarse
  // solve; an algebraic hierarchy whose file asks for MueLu's reuse is reused the same way. Either
  // gets its Chebyshev bounds re-estimated (MueLu 13.2 keeps the first matrix's), and is built
  // anew when MueLu cannot reuse it (it throws when what it kept no longer fits). The fine level's
  // grid-line blocks get a fresh damping either way.
  void setup(const HessianOperator& H, bool pattern_changed, const NearNullspace& modes) override {
    const Teuchos::RCP<crs_matrix_type> A = H.matrix();
    const SolverSettings& settings = config_.impl().settings;
    const bool grid_lines = settings.smoother_blocks == SmootherBlocks::grid_lines;
    if (pattern_changed) {
      geometric_levels_.clear();
      lines_.clear();
      whole_graph_ = false;
    }
    // A geometric hierarchy is always reused on the same pattern: its P is fixed, so MueLu only
    // refills the values of the Galerkin products it kept (no symbolic product, no allocation).
    const bool reuse = settings.prolongation == Prolongation::algebraic ? settings.muelu_reuse : true;
    if (!pattern_changed && !prec_.is_null() && reuse) {
      try {
        const SilencedStdout quiet;
        MueLu::ReuseTpetraPreconditioner(A, *prec_);
        refresh_reused_smoothers();
        finish_setup(H, *A, pattern_changed, modes);
        return;
      } catch (const std::exception&) {
        prec_ = Teuchos::null;  // built anew below, on the whole graph of A
        whole_graph_ = true;
      }
    }
    Teuchos::ParameterList params = *config_.impl().preconditioner_parameters;
    if (!params.isParameter("number of equations")) params.set("number of equations", 3);
    if (grid_lines) {
      if (lines_.empty()) lines_.resize(1);
      Teuchos::ParameterList& smoother = params.sublist("level 0").sublist("smoother: params");
      smoother = pattern_changed || lines_[0].list().numParams() == 0
                     ? lines_[0].prepare(smoother, *grid_of(modes), settings.line_length)
                     : lines_[0].list();
    }
    // The lean cycle smooths the fine level itself: MueLu builds no level-0 smoother.
    if (settings.cycle == Cycle::lean) params.sublist("level 0").set("smoother: pre or post", std::string("none"));
    {
      const SilencedStdout quiet;
      if (settings.prolongation == Prolongation::algebraic) setup_algebraic(A, params, modes);
      else setup_geometric(A, params, modes);
    }
    finish_setup(H, *A, pattern_changed, modes);
  }
  Teuchos::RCP<operator_type> op() const override {
    return lean_.is_null() ? Teuchos::rcp_implicit_cast<operator_type>(prec_) : Teuchos::rcp_implicit_cast<operator_type>(lean_);
  }
  Teuchos::RCP<const crs_matrix_type> level_matrix(int level) const override {
    if (prec_.is_null() || level >= prec_->GetHierarchy()->GetNumLevels()) return Teuchos::null;
    const auto A = prec_->GetHierarchy()->GetLevel(level)->template Get<Teuchos::RCP<xpetra_matrix_type>>("A");
    return muelu_utilities_type::Op2TpetraCrs(A);
  }
  std::vector<std::int64_t> level_rows() const override {
    std::vector<std::int64_t> rows;
    if (prec_.is_null()) return rows;
    const auto hierarchy = prec_->GetHierarchy();
    for (int level = 0; level < hierarchy->GetNumLevels(); ++level)
      rows.push_back(static_cast<std::int64_t>(
          hierarchy->GetLevel(level)->template Get<Teuchos::RCP<xpetra_matrix_type>>("A")->getGlobalNumRows()));
    return rows;
  }

 private:
  void setup_algebraic(const Teuchos::RCP<crs_matrix_type>& A, Teuchos::ParameterList& params,
                       const NearNullspace& modes) {
    Teuchos::ParameterList& user = params.sublist("user data");
    if (!modes.coordinates.is_null()) user.set("Coordinates", modes.coordinates);
    if (!modes.rigid_body_modes.is_null()) {
      if (config_.impl().settings.near_nullspace == NearNullspaceModes::translations) {
        Teuchos::RCP<multivector_type> translations = modes.rigid_body_modes->subCopy(Teuchos::Range1D(0, 2));
        user.set("Nullspace", translations);
      } else {
        user.set("Nullspace", modes.rigid_body_modes);
      }
    }
    // A hierarchy of one level would hand the whole (distributed) matrix to the coarse direct
    // solver, which is wrong on more than one rank here (doc/trilinos.md): always coarsen once,
    // so that the coarse level goes through repartitioning.
    const auto rows = static_cast<int>(A->getGlobalNumRows());
    if (rows <= params.get<int>("coarse: max size", 2000)) params.set("coarse: max size", std::max(1, rows / 8));
    prec_ = MueLu::CreateTpetraPreconditioner(Teuchos::rcp_static_cast<operator_type>(A), params);
  }

  // The grids 2Δx, 4Δx, ... as MueLu's levels: each level's P in its "level N" sublist. MueLu's
  // CreateTpetraPreconditioner hands its interpreter the list without the non-serialisable P,
  // which then aggregates anyway; built as below, the interpreter sees the P and uses it.
  void setup_geometric(const Teuchos::RCP<crs_matrix_type>& A, Teuchos::ParameterList& params,
                       const NearNullspace& modes) {
    if (!modes.grid) throw parameter_error(config_.origin(), "Prolongation", "geometric prolongators need the "
                                      "grid of the system (a scene, or a MatrixMarket dump with node coordinates)");
    const auto comm = A->getRowMap()->getComm();
    const parallel::Communicator communicator(*Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm)->getRawMpiComm());
    parallel::HierarchySettings settings;
    const Prolongation kind = config_.impl().settings.prolongation;
    settings.prolongation = kind == Prolongation::trilinear            ? parallel::Prolongation::trilinear
                            : kind == Prolongation::piecewise_constant ? parallel::Prolongation::piecewise_constant
                                                                       : parallel::Prolongation::quadratic_bspline;
    settings.max_levels = params.get<int>("max levels", 10);
    settings.coarsest_nodes = config_.impl().settings.coarsest_nodes;
    // The prolongators depend on the grid only: built once per pattern, with the coarse grids'
    // lines when the coarse levels smooth on them.
    const SolverSettings& solver_settings = config_.impl().settings;
    const int line_levels = solver_settings.smoother_blocks == SmootherBlocks::grid_lines ? solver_settings.line_levels : 0;
    const bool new_levels = geometric_levels_.empty();
    if (new_levels) {
      const auto levels = parallel::build_grid_hierarchy(communicator, modes.grid->dimensions, modes.grid->owned_nodes,
                                                         modes.grid->owner, settings);
      Teuchos::RCP<const map_type> fine = A->getRowMap();
      // Levels with smoothers: all but the coarsest, which is solved.
      lines_.resize(std::max<std::size_t>(1, std::min<std::size_t>(line_levels, levels.size())));
      for (std::size_t l = 0; l < levels.size(); ++l) {
        const auto& level = levels[l];
        Teuchos::RCP<const map_type> coarse;
        geometric_levels_.push_back(MueLu::TpetraCrs_To_XpetraMatrix(make_prolongator(level, fine, coarse)));
        fine = coarse;
        if (l + 1 < lines_.size()) {
          SystemGrid grid;
          grid.dimensions = level.dimensions;
          for (std::size_t k = 0; k < level.owned_count; ++k) grid.owned_nodes.push_back(node_index(level.nodes[k], level.dimensions));
          const Teuchos::ParameterList& fine_smoother = params.sublist("level 0").sublist("smoother: params");
          lines_[l + 1].prepare(fine_smoother, grid, solver_settings.line_length);
        }
      }
    }
    for (std::size_t l = 0; l < geometric_levels_.size(); ++l) {
      Teuchos::ParameterList& level = params.sublist("level " + std::to_string(l + 1));
      level.set("P", geometric_levels_[l]);
      if (l + 1 < lines_.size()) {
        level.set("smoother: type", params.sublist("level 0").get<std::string>("smoother: type"));
        level.sublist("smoother: params") = lines_[l + 1].list();
      }
    }
    // The P are the user's (kept above, per pattern); MueLu keeps the patterns of A·P and Pᵀ·A·P
    // and refills their values when the next set-up on the same pattern reuses the hierarchy.
    params.set("reuse: type", std::string("RP"));
    params.set("max levels", static_cast<int>(geometric_levels_.size()) + 1);
    params.set("coarse: max size", 1);
    Teuchos::ParameterList serializable, non_serializable;
    MueLu::ExtractNonSerializableData(params, serializable, non_serializable);
    muelu_interpreter_type interpreter(params, comm);
    Teuchos::RCP<muelu_hierarchy_type> hierarchy = interpreter.CreateHierarchy();
    hierarchy->setlib(Xpetra::UseTpetra);
    muelu_hierarchy_utils_type::AddNonSerializableDataToHierarchy(interpreter, *hierarchy, non_serializable);
    hierarchy->GetLevel(0)->Set("A", MueLu::TpetraCrs_To_XpetraMatrix(A));
    if (whole_graph_) {
      // Tpetra's product leaves out the entries of A that are zero now (node pairs no particle
      // couples yet), and reusing a product whose pattern misses entries that are nonzero later
      // throws. Once that happened on this pattern, the hierarchy is built with every entry of A's
      // graph present, so that the kept patterns cover any later values on it (at some cost: the
      // coarse levels then hold the couplings of the graph's padding too).
      const StructuralZeros filled(*A);
      interpreter.SetupHierarchy(*hierarchy);
    } else {
      interpreter.SetupHierarchy(*hierarchy);
    }
    prec_ = Teuchos::rcp(new muelu_operator_type(hierarchy));
  }

  // The Ifpack2 smoothers of a level (pre and post, one object or two; MueLu's interpreter wraps
  // them in a TrilinosSmoother).
  std::vector<Teuchos::RCP<muelu_ifpack2_smoother_type>> level_smoothers(int l) const {
    std::vector<Teuchos::RCP<muelu_ifpack2_smoother_type>> smoothers;
    const auto level = prec_->GetHierarchy()->GetLevel(l);
    for (const char* which : {"PreSmoother", "PostSmoother"}) {
      if (!level->IsAvailable(which)) continue;
      const auto held = level->template Get<Teuchos::RCP<muelu_smoother_type>>(which);
      auto smoother = Teuchos::rcp_dynamic_cast<muelu_ifpack2_smoother_type>(held);
      if (const auto wrapper = Teuchos::rcp_dynamic_cast<muelu_trilinos_smoother_type>(held); !wrapper.is_null())
        smoother = Teuchos::rcp_dynamic_cast<muelu_ifpack2_smoother_type>(wrapper->getSmoother());
      if (!smoother.is_null() && (smoothers.empty() || smoothers.back() != smoother)) smoothers.push_back(smoother);
    }
    return smoothers;
  }

  // MueLu 13.2 reuses a level's Ifpack2 smoothers and coarse solver on new values with compute()
  // alone, which keeps what their initialize() copied from the old matrix: the overlapping rows
  // of an additive Schwarz coarse solve, the block containers of a block relaxation. And it hands
  // a reused Chebyshev smoother the largest eigenvalue it estimated for the first matrix (cached
  // in the smoother's list). Each is initialised and computed again on its level's new matrix,
  // Chebyshev without the cached bound, so that Ifpack2 estimates it for the current one.
  void refresh_reused_smoothers() {
    for (int l = 0; l < prec_->GetHierarchy()->GetNumLevels(); ++l)
      for (const auto& smoother : level_smoothers(l)) {
        const auto preconditioner = smoother->getPreconditioner();
        if (preconditioner.is_null()) continue;
        if (auto chebyshev = Teuchos::rcp_dynamic_cast<Ifpack2::Chebyshev<row_matrix_type>>(preconditioner);
            !chebyshev.is_null()) {
          Teuchos::ParameterList& list = const_cast<Teuchos::ParameterList&>(smoother->GetParameterList());
          list.remove("chebyshev: max eigenvalue", false);
          Teuchos::ParameterList fresh = list;
          chebyshev->setParameters(fresh);
        }
        preconditioner->initialize();
        preconditioner->compute();
      }
  }

  // After MueLu's set-up: the grid-line smoothers' damping, and the lean cycle around the hierarchy.
  void finish_setup(const HessianOperator& H, const crs_matrix_type& A, bool pattern_changed, const NearNullspace& modes) {
    const SolverSettings& settings = config_.impl().settings;
    if (settings.smoother_blocks == SmootherBlocks::grid_lines) set_fine_smoother_damping(A);
    if (settings.cycle != Cycle::lean) return;
    // A grid at most Coarsest nodes large is one level, solved by the coarse solver: no cycle.
    if (prec_->GetHierarchy()->GetNumLevels() < 2) {
      lean_ = Teuchos::null;
      return;
    }
    if (pattern_changed || !lean_lines_)
      lean_lines_ = std::make_shared<LineSmoother>(grid::node_lines(grid_of(modes)->owned_nodes, settings.line_length));
    lean_lines_->compute(A, *H.op(), settings.line_damping);
    FineSmoothing smoothing;
    smoothing.steps = settings.fine_sweeps;
    smoothing.chebyshev = settings.fine_chebyshev;
    smoothing.ratio = settings.fine_chebyshev_ratio;
    smoothing.boost = settings.fine_chebyshev_boost;
    lean_ = Teuchos::rcp(new LeanCycle(H.op(), lean_lines_, prec_->GetHierarchy(), smoothing));
  }

  // The block relaxations on grid lines (pre- and post-smoother, one object or two) get their
  // damping: the fine level's (unless the lean cycle smooths it), and the coarse levels' of a
  // geometric hierarchy with Line levels.
  void set_fine_smoother_damping(const crs_matrix_type& A) {
    if (config_.impl().settings.cycle != Cycle::lean)
      for (const auto& smoother : level_smoothers(0))
        lines_[0].set_damping(*smoother->getPreconditioner(), A, config_.impl().settings);
    for (std::size_t l = 1; l < lines_.size() && static_cast<int>(l) < prec_->GetHierarchy()->GetNumLevels(); ++l) {
      const auto level_matrix = this->level_matrix(static_cast<int>(l));
      for (const auto& smoother : level_smoothers(static_cast<int>(l)))
        lines_[l].set_damping(*smoother->getPreconditioner(), *level_matrix, config_.impl().settings);
    }
  }

  SolverConfiguration config_;
  Teuchos::RCP<muelu_operator_type> prec_;
  std::vector<Teuchos::RCP<xpetra_matrix_type>> geometric_levels_;  // P of levels 1, 2, ... (this pattern)
  bool whole_graph_ = false;  // this pattern's hierarchy is built on every entry of A's graph
  std::vector<GridLines> lines_;  // per level that smooths on grid lines, finest first
  std::shared_ptr<LineSmoother> lean_lines_;  // Cycle = lean: the fine level's smoother
  Teuchos::RCP<LeanCycle> lean_;              // Cycle = lean: the preconditioner
};
}  // namespace

std::unique_ptr<Preconditioner> make_preconditioner(const SolverConfiguration& config) {
  switch (config.impl().settings.preconditioner) {
    case PreconditionerKind::ifpack2: return std::make_unique<Ifpack2Preconditioner>(config);
    case PreconditionerKind::muelu: return std::make_unique<MueLuPreconditioner>(config);
    case PreconditionerKind::jacobi: return std::make_unique<JacobiPreconditioner>();
    case PreconditionerKind::none: break;
  }
  return std::make_unique<NoPreconditioner>();
}

}  // namespace viscompm::linalg
