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

/// The top level of a solver file; its words are parsed once, into enums (the Krylov solver and
/// Ifpack2 type are names the libraries' factories take).
struct SolverSettings {
  std::string label;
  OperatorForm operator_form = OperatorForm::assembled;
  std::string krylov_solver = "Pseudo Block CG";
  PreconditionerKind preconditioner = PreconditionerKind::ifpack2;
  std::string ifpack2_type = "RELAXATION";
  Prolongation prolongation = Prolongation::algebraic;
  int coarsest_nodes = 2000;
  NearNullspaceModes near_nullspace = NearNullspaceModes::rigid_body_modes;
  SmootherBlocks smoother_blocks = SmootherBlocks::library;
  int line_length = 16;
  double line_damping = 1.5;
  int max_ranks = 0;

  static const ParameterTable<SolverSettings>& table();
};

/// Ifpack2's names of its block relaxation.
inline bool is_block_relaxation(const std::string& type) {
  return type == "BLOCK_RELAXATION" || type == "BLOCK RELAXATION" || type == "BLOCKRELAXATION";
}

struct SolverConfiguration::Impl {
  std::string origin;
  SolverSettings settings;
  Teuchos::RCP<Teuchos::ParameterList> krylov_parameters;
  Teuchos::RCP<Teuchos::ParameterList> preconditioner_parameters;
};

}  // namespace viscompm::linalg
