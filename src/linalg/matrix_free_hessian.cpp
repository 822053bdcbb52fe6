// H applied without assembling it — the paper's solver (§5.7): the same per-particle 9×9
// pieces ∂²Φ_p/∂A², applied as y_i = Δt² Σ_p P_i (H_p : (Σ_j P_j x_j ⊗ ∇w_jp)) ∇w_ip + m_i x_i,
// with shared nodes summed into their owners. Its exact diagonal feeds the Jacobi
// preconditioner.
#include "hessian_operator.hpp"

namespace viscompm::linalg {

namespace {
class MatrixFreeHessian : public HessianOperator {
 public:
  explicit MatrixFreeHessian(const NodeSpace& space) : space_(space), apply_(Teuchos::rcp(new Apply(*this))) {}

  bool update(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    potential_ = &potential;
    const double dt2 = potential.dt() * potential.dt();
    hessians_ = potential.particle_hessians(v, project);
    for (Mat9& h : hessians_) h *= dt2;
    // Per particle, the weight gradients of its stencil nodes (reused by every product).
    const grid::GridLayout& layout = potential.layout();
    const int K = layout.nodes_per_cell();
    gradients_.resize(hessians_.size() * K);
    for (std::size_t c = 0; c < layout.cell_count(); ++c)
      for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p)
        grid::for_each_stencil_node(layout, c, p, [&](int k, int, double, const Vec3& dw) { gradients_[p * K + k] = dw; });
    free_.resize(layout.local_node_count());
    for (std::size_t i = 0; i < free_.size(); ++i) free_[i] = potential.constraints().projection[i] == Mat3::Identity();
    const bool changed = space_.version() != space_version_;
    if (changed) {
      space_version_ = space_.version();
      ++builds_;
      const auto& s = space_.impl();
      x_local_ = Teuchos::rcp(new multivector_type(s.local_dof_map, 1));
      y_local_ = Teuchos::rcp(new multivector_type(s.local_dof_map, 1));
      y_owned_ = Teuchos::rcp(new multivector_type(s.owned_dof_map, 1));
    }
    compute_diagonal();
    return changed;
  }
  Teuchos::RCP<const operator_type> op() const override { return apply_; }
  Teuchos::RCP<crs_matrix_type> matrix() const override { return Teuchos::null; }
  Teuchos::RCP<const vector_type> diagonal() const override { return diagonal_; }
  std::int64_t nonzeros() const override { return -1; }
  int pattern_builds() const override { return builds_; }

 private:
  class Apply : public operator_type {
   public:
    explicit Apply(MatrixFreeHessian& h) : h_(h) {}
    Teuchos::RCP<const map_type> getDomainMap() const override { return h_.space_.impl().owned_dof_map; }
    Teuchos::RCP<const map_type> getRangeMap() const override { return h_.space_.impl().owned_dof_map; }
    void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp, scalar_type alpha,
               scalar_type beta) const override {
      for (std::size_t j = 0; j < X.getNumVectors(); ++j) h_.apply_column(*X.getVector(j), *Y.getVectorNonConst(j), alpha, beta);
    }

   private:
    MatrixFreeHessian& h_;
  };

  void apply_column(const vector_type& x, vector_type& y, double alpha, double beta) const;
  void compute_diagonal();

  const NodeSpace& space_;
  Teuchos::RCP<Apply> apply_;
  const implicit::IncrementalPotential* potential_ = nullptr;
  std::vector<Mat9> hessians_;  // Δt² ∂²Φ_p/∂A², per particle
  std::vector<Vec3> gradients_;  // ∇w of each particle's stencil nodes
  std::vector<char> free_;       // node without constraint
  mutable NodeVectorField x_nodes_, y_nodes_;
  Teuchos::RCP<vector_type> diagonal_;
  Teuchos::RCP<multivector_type> x_local_, y_local_, y_owned_;
  std::uint64_t space_version_ = 0;
  int builds_ = 0;
};

void MatrixFreeHessian::apply_column(const vector_type& x, vector_type& y, double alpha, double beta) const {
  const auto& s = space_.impl();
  const grid::GridLayout& layout = potential_->layout();
  const auto& P = potential_->constraints().projection;
  const int K = layout.nodes_per_cell();
  x_local_->doImport(x, *s.dof_import, Tpetra::INSERT);
  const std::size_t n = layout.local_node_count();
  x_nodes_.resize(n);
  y_nodes_.assign(n, Vec3::Zero());
  {
    auto view = x_local_->getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < n; ++i) {
      x_nodes_[i] = Vec3(view(3 * i, 0), view(3 * i + 1, 0), view(3 * i + 2, 0));
      if (!free_[i]) x_nodes_[i] = P[i] * x_nodes_[i];
    }
  }
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      // δA = Σ_j x_j ∇w_jᵀ, T = H_p δA, then y_i += T ∇w_i.
      const Vec3* dw = gradients_.data() + p * K;
      Mat3 dA = Mat3::Zero();
      for (int k = 0; k < K; ++k) dA.noalias() += x_nodes_[nodes[k]] * dw[k].transpose();
      const Mat3 T = unvec(hessians_[p] * vec(dA));
      for (int k = 0; k < K; ++k) y_nodes_[nodes[k]].noalias() += T * dw[k];
    }
  }
  {
    auto view = y_local_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 yi = free_[i] ? y_nodes_[i] : Vec3(P[i] * y_nodes_[i]);
      for (int d = 0; d < 3; ++d) view(3 * i + d, 0) = yi[d];
    }
  }
  y_owned_->putScalar(0.0);
  y_owned_->doExport(*y_local_, *s.dof_export, Tpetra::ADD);
  {
    // The inertia m_i x_i on owned rows, then Y = α H x + β Y.
    auto h = y_owned_->getLocalViewHost(Tpetra::Access::ReadWrite);
    auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < layout.owned_count; ++i)
      for (int d = 0; d < 3; ++d) h(3 * i + d, 0) += potential_->mass()[i] * xv(3 * i + d, 0);
  }
  y.update(alpha, *y_owned_->getVector(0), beta);
}

void MatrixFreeHessian::compute_diagonal() {
  const auto& s = space_.impl();
  const grid::GridLayout& layout = potential_->layout();
  const auto& P = potential_->constraints().projection;
  const std::size_t n = layout.local_node_count();
  // Node blocks B_ii = Σ_p Σ_{βκ} ∇w_i[β] H_p(σ+3β, τ+3κ) ∇w_i[κ], then diag(P B P).
  std::vector<Mat3> blocks(n, Mat3::Zero());
  for (std::size_t c = 0; c < layout.cell_count(); ++c)
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      const Mat9& H = hessians_[p];
      grid::for_each_stencil_node(layout, c, p, [&](int, int i, double, const Vec3& dw) {
        for (int beta = 0; beta < 3; ++beta)
          for (int kappa = 0; kappa < 3; ++kappa)
            blocks[i] += dw[beta] * dw[kappa] * H.block<3, 3>(3 * beta, 3 * kappa);
      });
    }
  multivector_type local(s.local_dof_map, 1);
  {
    auto view = local.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 d = (P[i] * blocks[i] * P[i]).diagonal();
      for (int k = 0; k < 3; ++k) view(3 * i + k, 0) = d[k];
    }
  }
  diagonal_ = Teuchos::rcp(new vector_type(s.owned_dof_map));
  diagonal_->doExport(local, *s.dof_export, Tpetra::ADD);
  auto view = diagonal_->getLocalViewHost(Tpetra::Access::ReadWrite);
  for (std::size_t i = 0; i < layout.owned_count; ++i)
    for (int d = 0; d < 3; ++d) view(3 * i + d, 0) += potential_->mass()[i];
}
}  // namespace

std::unique_ptr<HessianOperator> make_matrix_free_hessian(const NodeSpace& space) {
  return std::make_unique<MatrixFreeHessian>(space);
}

}  // namespace viscompm::linalg
