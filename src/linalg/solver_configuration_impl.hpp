// Tpetra/Teuchos side of SolverConfiguration, shared by the linear-algebra translation units.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include "viscompm/core/parameters.hpp"
#include "viscompm/linalg/linear_solver.hpp"

namespace viscompm::linalg {

/// The top level of a solver file.
struct SolverSettings {
  std::string label;
  std::string operator_form = "assembled";
  std::string krylov_solver = "Pseudo Block CG";
  std::string preconditioner = "Ifpack2";
  std::string ifpack2_type = "RELAXATION";
  std::string prolongation = "algebraic";
  int coarsest_nodes = 2000;
  std::string near_nullspace = "rigid body modes";

  static const ParameterTable<SolverSettings>& table();
};

struct SolverConfiguration::Impl {
  std::string origin;
  SolverSettings settings;
  Teuchos::RCP<Teuchos::ParameterList> krylov_parameters;
  Teuchos::RCP<Teuchos::ParameterList> preconditioner_parameters;
};

}  // namespace viscompm::linalg
