// The preconditioners: none, Ifpack2 (any Ifpack2::Factory type) and MueLu smoothed
// aggregation with coordinates and rigid-body near-nullspace in its "user data".
#include <Ifpack2_Factory.hpp>
#include <MueLu_CreateTpetraPreconditioner.hpp>

#include "krylov.hpp"
#include "viscompm/core/error.hpp"

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

class Ifpack2Preconditioner : public Preconditioner {
 public:
  explicit Ifpack2Preconditioner(const SolverConfiguration& config) : config_(config) {}
  void setup(const HessianOperator& H, bool pattern_changed, const NearNullspace&) override {
    const Teuchos::RCP<crs_matrix_type> A = H.matrix();
    if (pattern_changed || prec_.is_null()) {
      prec_ = Ifpack2::Factory::create<Tpetra::RowMatrix<scalar_type, local_ordinal_type, global_ordinal_type, node_type>>(
          config_.impl().settings.ifpack2_type, A);
      if (prec_.is_null())
        throw InputError(config_.origin() + ": parameter 'Ifpack2 type': unknown Ifpack2 preconditioner '" +
                         config_.impl().settings.ifpack2_type + "'");
      Teuchos::ParameterList params = *config_.impl().preconditioner_parameters;
      // 3×3 point-block relaxation: one block per node (a node's three dofs are consecutive).
      if (config_.impl().settings.ifpack2_type == "BLOCK_RELAXATION" && !params.isParameter("partitioner: local parts"))
        params.set("partitioner: local parts", static_cast<local_ordinal_type>(A->getNodeNumRows() / 3));
      prec_->setParameters(params);
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
  void setup(const HessianOperator& H, bool pattern_changed, const NearNullspace& modes) override {
    const Teuchos::RCP<crs_matrix_type> A = H.matrix();
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
    // A hierarchy of one level would hand the whole (distributed) matrix to the coarse direct
    // solver, which is wrong on more than one rank here (DESIGN.md §5): always coarsen once, so
    // that the coarse level goes through repartitioning.
    const auto rows = static_cast<int>(A->getGlobalNumRows());
    if (rows <= params.get<int>("coarse: max size", 2000)) params.set("coarse: max size", std::max(1, rows / 8));
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
  if (kind == "Jacobi") return std::make_unique<JacobiPreconditioner>();
  return std::make_unique<NoPreconditioner>();
}

}  // namespace viscompm::linalg
