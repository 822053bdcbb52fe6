// The one place that spells the Tpetra template arguments. This Trilinos is instantiated for
// Scalar = double, LocalOrdinal = int, GlobalOrdinal = long long on the Kokkos Serial node; no
// other file repeats them. Private to src/linalg (not installed; Trilinos headers are slow to
// compile and no Tpetra type leaks out of the linear-algebra layer).
#pragma once

#include <Ifpack2_Preconditioner.hpp>
#include <MueLu_HierarchyUtils_fwd.hpp>
#include <MueLu_Hierarchy_fwd.hpp>
#include <MueLu_ParameterListInterpreter_fwd.hpp>
#include <MueLu_Utilities_fwd.hpp>
#include <MueLu_TpetraOperator_fwd.hpp>
#include <MueLu_SmootherBase_fwd.hpp>
#include <MueLu_Ifpack2Smoother_fwd.hpp>
#include <MueLu_TrilinosSmoother_fwd.hpp>
#include <Tpetra_BlockCrsMatrix_fwd.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_RowMatrix_fwd.hpp>
#include <Xpetra_Matrix_fwd.hpp>
#include <Tpetra_Export.hpp>
#include <Tpetra_FECrsGraph.hpp>
#include <Tpetra_FECrsMatrix.hpp>
#include <Tpetra_Import.hpp>
#include <Tpetra_Map.hpp>
#include <Tpetra_MultiVector.hpp>
#include <Tpetra_Operator.hpp>
#include <Tpetra_Vector.hpp>

namespace viscompm::linalg {

using scalar_type = double;
using local_ordinal_type = int;
using global_ordinal_type = long long;
using node_type = Tpetra::Map<>::node_type;

using map_type = Tpetra::Map<local_ordinal_type, global_ordinal_type, node_type>;
using import_type = Tpetra::Import<local_ordinal_type, global_ordinal_type, node_type>;
using export_type = Tpetra::Export<local_ordinal_type, global_ordinal_type, node_type>;
using multivector_type = Tpetra::MultiVector<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using vector_type = Tpetra::Vector<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using operator_type = Tpetra::Operator<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using crs_graph_type = Tpetra::CrsGraph<local_ordinal_type, global_ordinal_type, node_type>;
using crs_matrix_type = Tpetra::CrsMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using block_crs_matrix_type = Tpetra::BlockCrsMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using fe_graph_type = Tpetra::FECrsGraph<local_ordinal_type, global_ordinal_type, node_type>;
using fe_matrix_type = Tpetra::FECrsMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using row_matrix_type = Tpetra::RowMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using ifpack2_preconditioner_type =
    Ifpack2::Preconditioner<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using xpetra_matrix_type = Xpetra::Matrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_hierarchy_type = MueLu::Hierarchy<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_operator_type = MueLu::TpetraOperator<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_interpreter_type =
    MueLu::ParameterListInterpreter<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_hierarchy_utils_type = MueLu::HierarchyUtils<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_utilities_type = MueLu::Utilities<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_smoother_type = MueLu::SmootherBase<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_ifpack2_smoother_type = MueLu::Ifpack2Smoother<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;
using muelu_trilinos_smoother_type =
    MueLu::TrilinosSmoother<scalar_type, local_ordinal_type, global_ordinal_type, node_type>;

static_assert(std::is_same_v<global_ordinal_type, map_type::global_ordinal_type>);

}  // namespace viscompm::linalg
