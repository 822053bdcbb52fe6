// Tpetra/Teuchos side of SolverConfiguration, shared by the linear-algebra translation units.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include "viscompm/core/parameters.hpp"
#include "viscompm/linalg/linear_solver.hpp"

namespace viscompm::linalg {

enum class OperatorForm { assembled, matrix_free };
enum class PreconditionerKind { none, jacobi, ifpack2, muelu };
/// MueLu's own aggregation, or prolongators between the grids Δx, 2Δx, 4Δx, ...
enum class Prolongation { algebraic, trilinear, quadratic_bspline, piecewise_constant };
enum class NearNullspaceModes { rigid_body_modes, translations };
/// Where the blocks of the fine level's BLOCK_RELAXATION smoother come from.
enum class SmootherBlocks { library, grid_lines };
/// The one Ifpack2 type viscompm treats apart (one block per node unless told otherwise).
enum class Ifpack2Kind { block_relaxation, other };
/// How a block relaxation combines its blocks (Ifpack2's "relaxation: type" of the smoother that
/// gets the grid lines): additively, which needs a damping, or symmetric Gauss-Seidel.
enum class BlockCombination { jacobi, symmetric_gauss_seidel };
/// Who applies a MueLu hierarchy's fine level: MueLu (its smoother objects), or viscompm (lean).
enum class Cycle { muelu, lean };
/// A coarse space added to the preconditioner: none, or the rigid motions of the stiff bodies.
enum class Deflation { none, stiff_bodies };

/// The top level of a solver file; its words are parsed once, into enums (the Krylov solver and
/// Ifpack2 type are names the libraries' factories take), and so are the few words of the
/// libraries' own lists that viscompm acts on (block relaxation, the lines' combination, MueLu's
/// reuse): nothing below the reader compares a configuration word.
struct SolverSettings {
  std::string label;
  OperatorForm operator_form = OperatorForm::assembled;
  std::string krylov_solver = "Pseudo Block CG";
  PreconditionerKind preconditioner = PreconditionerKind::ifpack2;
  std::string ifpack2_type = "RELAXATION";  ///< block relaxation's three spellings as BLOCK_RELAXATION
  Ifpack2Kind ifpack2_kind = Ifpack2Kind::other;
  Prolongation prolongation = Prolongation::algebraic;
  int coarsest_nodes = 2000;
  NearNullspaceModes near_nullspace = NearNullspaceModes::rigid_body_modes;
  SmootherBlocks smoother_blocks = SmootherBlocks::library;
  int line_length = 16;
  double line_damping = 1.5;
  int line_levels = 1;  ///< geometric hierarchies: the finest this many levels smooth on grid lines
  Cycle cycle = Cycle::muelu;
  int fine_sweeps = 1;  ///< lean cycle: line-smoother sweeps (or Chebyshev degree) before and after the coarse correction
  bool fine_chebyshev = false;   ///< lean cycle: Chebyshev steps on the line blocks instead of damped sweeps
  double fine_chebyshev_ratio = 20.0;
  double fine_chebyshev_boost = 1.1;
  Deflation deflation = Deflation::none;
  double stiff_cfl = 30.0;    ///< c Δt/Δx from which a material counts as stiff (deflation)
  int max_stiff_bodies = 64;  ///< the largest this many bodies are deflated
  int max_ranks = 0;
  BlockCombination line_combination = BlockCombination::jacobi;  ///< of the grid-line smoother
  bool muelu_reuse = false;  ///< MueLu's "reuse: type" is given and not "none"

  static const ParameterTable<SolverSettings>& table();
};

struct SolverConfiguration::Impl {
  std::string origin;
  SolverSettings settings;
  Teuchos::RCP<Teuchos::ParameterList> krylov_parameters;
  Teuchos::RCP<Teuchos::ParameterList> preconditioner_parameters;
  std::vector<SolverConfiguration> candidates;  ///< a measured choice's (empty: one configuration)
  SolverChoiceSettings choice;
};

}  // namespace viscompm::linalg
