// The preconditioners: none, Ifpack2 (any Ifpack2::Factory type) and MueLu smoothed
// aggregation with coordinates and rigid-body near-nullspace in its "user data".
#include <Ifpack2_Factory.hpp>
#include <MueLu_CreateTpetraPreconditioner.hpp>

#include "krylov.hpp"
#include "viscompm/core/error.hpp"

namespace viscompm::linalg {

namespace {
class NoPreconditioner : public Preconditioner {
 public:
  void setup(const Teuchos::RCP<crs_matrix_type>&, bool, const NearNullspace&) override {}
  Teuchos::RCP<operator_type> op() const override { return Teuchos::null; }
};

class Ifpack2Preconditioner : public Preconditioner {
 public:
  explicit Ifpack2Preconditioner(const SolverConfiguration& config) : config_(config) {}
  void setup(const Teuchos::RCP<crs_matrix_type>& A, bool pattern_changed, const NearNullspace&) override {
    if (pattern_changed || prec_.is_null()) {
      prec_ = Ifpack2::Factory::create<Tpetra::RowMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>>(
          config_.impl().settings.ifpack2_type, A);
      if (prec_.is_null())
        throw InputError(config_.origin() + ": parameter 'Ifpack2 type': unknown Ifpack2 preconditioner '" +
                         config_.impl().settings.ifpack2_type + "'");
      prec_->setParameters(*config_.impl().preconditioner_parameters);
      prec_->initialize();
    }
    prec_->compute();  // new values, same pattern
  }
  Teuchos::RCP<operator_type> op() const override { return prec_; }

 private:
  SolverConfiguration config_;
  Teuchos::RCP<Ifpack2::Preconditioner<scalar_type, local_ordinal_type, global_ordinal_type, node_type>> prec_;
};

class MueLuPreconditioner : public Preconditioner {
 public:
  explicit MueLuPreconditioner(const SolverConfiguration& config) : config_(config) {}
  void setup(const Teuchos::RCP<crs_matrix_type>& A, bool pattern_changed, const NearNullspace& modes) override {
    const bool reuse = config_.impl().preconditioner_parameters->get<std::string>("reuse: type", "none") != "none";
    if (!pattern_changed && reuse && !prec_.is_null()) {
      MueLu::ReuseTpetraPreconditioner(A, *prec_);
      return;
    }
    Teuchos::ParameterList params = *config_.impl().preconditioner_parameters;
    Teuchos::ParameterList& user = params.sublist("user data");
    if (!modes.coordinates.is_null()) user.set("Coordinates", modes.coordinates);
    if (!modes.rigid_body_modes.is_null()) user.set("Nullspace", modes.rigid_body_modes);
    if (!params.isParameter("number of equations")) params.set("number of equations", 3);
    prec_ = MueLu::CreateTpetraPreconditioner(Teuchos::rcp_static_cast<operator_type>(A), params);
  }
  Teuchos::RCP<operator_type> op() const override { return prec_; }

 private:
  SolverConfiguration config_;
  Teuchos::RCP<MueLu::TpetraOperator<scalar_type, local_ordinal_type, global_ordinal_type, node_type>> prec_;
};
}  // namespace

std::unique_ptr<Preconditioner> make_preconditioner(const SolverConfiguration& config) {
  const std::string& kind = config.impl().settings.preconditioner;
  if (kind == "Ifpack2") return std::make_unique<Ifpack2Preconditioner>(config);
  if (kind == "MueLu") return std::make_unique<MueLuPreconditioner>(config);
  return std::make_unique<NoPreconditioner>();
}

}  // namespace viscompm::linalg
