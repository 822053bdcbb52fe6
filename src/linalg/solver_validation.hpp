// Validation of the library parameter lists of a solver file when it is read, before anything is
// set up (Belos, Ifpack2, MueLu): names, types and values, checked with the libraries' own lists
// of valid parameters, validators, factories and MueLu's interpreter. Each problem ends the run
// with one InputError line naming the file and the parameter path (exit code 2).
#pragma once

#include <Teuchos_ParameterList.hpp>
#include <string>

namespace viscompm::linalg {

/// Belos: names and types against the solver's valid parameters; finite positive tolerances and
/// iteration counts (Belos has no validators for them).
void validate_krylov_parameters(const Teuchos::ParameterList& given, const Teuchos::ParameterList& valid,
                                const std::string& origin, const std::string& path);

/// An Ifpack2 preconditioner of `type` (Ifpack2::Factory name) with parameters `given`.
/// `type_parameter` names where the type came from (for messages).
void validate_ifpack2_parameters(const std::string& type, const Teuchos::ParameterList& given, const std::string& origin,
                                 const std::string& type_parameter, const std::string& path);

/// A MueLu parameter list: names and types against MueLu::MasterList, smoother and coarse solver
/// types against Ifpack2's and Amesos2's factories (and their parameters as Ifpack2 lists), then
/// MueLu::ParameterListInterpreter's own checks of the values.
void validate_muelu_parameters(const Teuchos::ParameterList& given, const std::string& origin, const std::string& path);

}  // namespace viscompm::linalg
