#include "viscompm/linalg/linear_solver.hpp"

#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>

#include "solver_configuration_impl.hpp"
#include "solver_validation.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/linalg/linalg_types.hpp"
#include "viscompm/params/parameter_io.hpp"

namespace viscompm::linalg {

const ParameterTable<SolverSettings>& SolverSettings::table() {
  static const ParameterTable<SolverSettings> t = [] {
    ParameterTable<SolverSettings> table;
    using S = SolverSettings;
    table.string(&S::label, "Label", "", {}, "name of this configuration in solver.csv and study.csv")
        .string(&S::operator_form, "Operator", "assembled", {"assembled", "matrix-free"},
                "assembled Tpetra matrix, or the paper's matrix-free Hessian-vector product (§5.7)")
        .string(&S::krylov_solver, "Krylov solver", "Pseudo Block CG", {"Pseudo Block CG", "Block CG"},
                "Belos solver (Pseudo Block CG is Belos' CG)")
        .string(&S::preconditioner, "Preconditioner", "Ifpack2", {"none", "Jacobi", "Ifpack2", "MueLu"},
                "none; Jacobi (exact diagonal of H, also matrix-free); Ifpack2 or MueLu (assembled only)")
        .string(&S::ifpack2_type, "Ifpack2 type", "RELAXATION", {}, "Ifpack2::Factory name (RELAXATION, CHEBYSHEV, ...)")
        .string(&S::prolongation, "Prolongation", "algebraic", {"algebraic", "trilinear", "quadratic B-spline", "piecewise constant"},
                "MueLu: the prolongators of its own aggregation (algebraic), or geometric ones between the grids "
                "Δx, 2Δx, 4Δx, ... (trilinear, the coarse quadratic B-spline at the fine nodes, or piecewise "
                "constant: 2×2×2-node aggregates, unsmoothed)")
        .integer(&S::coarsest_nodes, "Coarsest nodes", 2000, Range::at_least(1),
                 "geometric prolongation: coarsen until a level has at most this many nodes")
        .string(&S::near_nullspace, "Near nullspace", "rigid body modes", {"rigid body modes", "translations"},
                "algebraic MueLu: the modes its aggregates must represent (the 6 rigid-body modes, or the 3 "
                "translations, for aggregates of a node or two)");
    return table;
  }();
  return t;
}

namespace {
constexpr const char* krylov_sublist = "Krylov parameters";
constexpr const char* preconditioner_sublist = "Preconditioner parameters";

std::shared_ptr<SolverConfiguration::Impl> parse(const Teuchos::ParameterList& list, const std::string& origin) {
  auto impl = std::make_shared<SolverConfiguration::Impl>();
  impl->origin = origin;
  const ParameterValues values =
      params::read_parameters(list, SolverSettings::table().specs(), origin, "", {krylov_sublist, preconditioner_sublist});
  impl->settings = SolverSettings::table().parse(values);
  SolverSettings& s = impl->settings;

  impl->krylov_parameters = Teuchos::rcp(new Teuchos::ParameterList(
      list.isSublist(krylov_sublist) ? list.sublist(krylov_sublist) : Teuchos::ParameterList()));
  impl->preconditioner_parameters = Teuchos::rcp(new Teuchos::ParameterList(
      list.isSublist(preconditioner_sublist) ? list.sublist(preconditioner_sublist) : Teuchos::ParameterList()));

  // Belos, Ifpack2 and MueLu know their parameters: a misspelled name, a wrong type or a bad value
  // is bad input now rather than a failure (or a hang) once particles are sampled and solved.
  Belos::SolverFactory<scalar_type, multivector_type, operator_type> factory;
  auto solver = factory.create(s.krylov_solver, Teuchos::null);
  validate_krylov_parameters(*impl->krylov_parameters, *solver->getValidParameters(), origin, krylov_sublist);

  if (s.operator_form == "matrix-free" && (s.preconditioner == "Ifpack2" || s.preconditioner == "MueLu"))
    throw InputError(origin + ": parameter 'Preconditioner': " + s.preconditioner +
                     " needs the assembled matrix (Operator = assembled)");
  if (s.preconditioner == "Ifpack2")
    validate_ifpack2_parameters(s.ifpack2_type, *impl->preconditioner_parameters, origin, "Ifpack2 type",
                                preconditioner_sublist);
  if (s.preconditioner == "MueLu") validate_muelu_parameters(*impl->preconditioner_parameters, origin, preconditioner_sublist);
  if ((s.preconditioner == "none" || s.preconditioner == "Jacobi") && impl->preconditioner_parameters->numParams() > 0)
    throw InputError(origin + ": parameter '" + preconditioner_sublist + "': " + s.preconditioner +
                     " takes no parameters");
  if (s.prolongation != "algebraic" && s.preconditioner != "MueLu")
    throw InputError(origin + ": parameter 'Prolongation': geometric prolongators are for Preconditioner = MueLu");
  if (s.label.empty()) {
    s.label = (s.operator_form == "matrix-free" ? "matrix-free " : "") +
              (s.preconditioner == "Ifpack2" ? "Ifpack2 " + s.ifpack2_type : s.preconditioner);
    if (impl->preconditioner_parameters->isParameter("relaxation: type"))
      s.label += " " + impl->preconditioner_parameters->get<std::string>("relaxation: type");
  }
  return impl;
}
}  // namespace

SolverConfiguration SolverConfiguration::read(const std::string& file) {
  SolverConfiguration c;
  c.impl_ = parse(*params::read_xml_file(file), file);
  return c;
}

SolverConfiguration SolverConfiguration::from_xml(const std::string& xml, const std::string& origin) {
  SolverConfiguration c;
  Teuchos::RCP<Teuchos::ParameterList> list;
  try {
    list = Teuchos::getParametersFromXmlString(xml);
  } catch (const std::exception& e) {
    throw InputError(origin + ": not a valid XML parameter list");
  }
  c.impl_ = parse(*list, origin);
  return c;
}

const std::string& SolverConfiguration::label() const { return impl_->settings.label; }
const std::string& SolverConfiguration::origin() const { return impl_->origin; }
bool SolverConfiguration::matrix_free() const { return impl_->settings.operator_form == "matrix-free"; }

}  // namespace viscompm::linalg
