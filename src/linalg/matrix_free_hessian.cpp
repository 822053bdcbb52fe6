// H applied without assembling it — the paper's solver (§5.7): the same per-particle 9×9
// pieces Δt² ∂²Φ_p/∂A², applied as y_i = Σ_p P_i (H_p : (Σ_j P_j x_j ⊗ ∇w_jp)) ∇w_ip + m_i x_i
// on the owned nodes, from own and ghost particles after x is imported to the ghost nodes. Its
// exact diagonal feeds the Jacobi preconditioner.
#include "hessian_operator.hpp"

namespace viscompm::linalg {

namespace {
class MatrixFreeHessian : public HessianOperator {
 public:
  explicit MatrixFreeHessian(const NodeSpace& space) : space_(space), apply_(Teuchos::rcp(new Apply(*this))) {}

  void build_pattern() override {
    x_column_ = Teuchos::rcp(new vector_type(space_.impl().column_dof_map));
  }
  void update(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    potential_ = &potential;
    hessians_ = potential.particle_hessians(v, project);
    // Per particle, the weight gradients of its stencil nodes (reused by every product).
    const grid::GridLayout& layout = potential.layout();
    const int K = layout.nodes_per_cell();
    gradients_.resize(hessians_.size() * K);
    for (std::size_t c = 0; c < layout.cell_count(); ++c)
      for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p)
        grid::for_each_stencil_node(layout, c, p, [&](int k, int, double, const Vec3& dw) { gradients_[p * K + k] = dw; });
    free_.resize(layout.local_node_count());
    for (std::size_t i = 0; i < free_.size(); ++i) free_[i] = potential.is_free(i);
    diagonal_mass_.resize(layout.owned_count);
    const double scale = massless_row_scale(potential, space_.comm());
    for (std::size_t i = 0; i < layout.owned_count; ++i)
      diagonal_mass_[i] = potential.mass()[i] > 0.0 ? potential.mass()[i] : scale;
    compute_diagonal();
  }
  Teuchos::RCP<const operator_type> op() const override { return apply_; }
  Teuchos::RCP<crs_matrix_type> matrix() const override { return Teuchos::null; }
  Teuchos::RCP<const vector_type> diagonal() const override { return diagonal_; }
  std::int64_t nonzeros() const override { return -1; }

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
  std::vector<Mat9> hessians_;   // Δt² ∂²Φ_p/∂A², per particle (own and ghost)
  std::vector<Vec3> gradients_;  // ∇w of each particle's stencil nodes
  std::vector<char> free_;       // node without constraint
  std::vector<double> diagonal_mass_;  // m_i, or the massless-row scale
  mutable NodeVectorField x_nodes_, y_nodes_;
  Teuchos::RCP<vector_type> diagonal_;
  Teuchos::RCP<vector_type> x_column_;
};

void MatrixFreeHessian::apply_column(const vector_type& x, vector_type& y, double alpha, double beta) const {
  const auto& s = space_.impl();
  const grid::GridLayout& layout = potential_->layout();
  const auto& P = potential_->constraints().projection;
  const int K = layout.nodes_per_cell();
  const int owned = static_cast<int>(layout.owned_count);
  x_column_->doImport(x, *s.dof_import, Tpetra::INSERT);
  const std::size_t n = layout.local_node_count();
  x_nodes_.resize(n);
  y_nodes_.assign(layout.owned_count, Vec3::Zero());
  {
    auto view = x_column_->getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < n; ++i) {
      x_nodes_[i] = Vec3(view(3 * i, 0), view(3 * i + 1, 0), view(3 * i + 2, 0));
      if (!free_[i]) x_nodes_[i] = P[i] * x_nodes_[i];
    }
  }
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    const int* nodes = layout.nodes_of_cell(c);
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      // δA = Σ_j x_j ∇w_jᵀ, T = H_p δA, then y_i += T ∇w_i on owned nodes.
      const Vec3* dw = gradients_.data() + p * K;
      Mat3 dA = Mat3::Zero();
      for (int k = 0; k < K; ++k) dA.noalias() += x_nodes_[nodes[k]] * dw[k].transpose();
      const Mat3 T = unvec(hessians_[p] * vec(dA));
      for (int k = 0; k < K; ++k)
        if (nodes[k] < owned) y_nodes_[nodes[k]].noalias() += T * dw[k];
    }
  }
  // Projection, the inertia m_i x_i, then Y = α H x + β Y.
  auto yv = y.getLocalViewHost(Tpetra::Access::ReadWrite);
  auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (int i = 0; i < owned; ++i) {
    const Vec3 yi = free_[i] ? y_nodes_[i] : Vec3(P[i] * y_nodes_[i]);
    for (int d = 0; d < 3; ++d) {
      const double h = yi[d] + diagonal_mass_[i] * xv(3 * i + d, 0);
      yv(3 * i + d, 0) = beta == 0.0 ? alpha * h : alpha * h + beta * yv(3 * i + d, 0);
    }
  }
}

void MatrixFreeHessian::compute_diagonal() {
  const auto& s = space_.impl();
  const grid::GridLayout& layout = potential_->layout();
  const auto& P = potential_->constraints().projection;
  const int owned = static_cast<int>(layout.owned_count);
  // Node blocks B_ii = Σ_p Σ_{βκ} ∇w_i[β] H_p(σ+3β, τ+3κ) ∇w_i[κ], then diag(P B P).
  std::vector<Mat3> blocks(layout.owned_count, Mat3::Zero());
  for (std::size_t c = 0; c < layout.cell_count(); ++c)
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      const Mat9& H = hessians_[p];
      grid::for_each_stencil_node(layout, c, p, [&](int, int i, double, const Vec3& dw) {
        if (i >= owned) return;
        for (int beta = 0; beta < 3; ++beta)
          for (int kappa = 0; kappa < 3; ++kappa)
            blocks[i] += dw[beta] * dw[kappa] * H.block<3, 3>(3 * beta, 3 * kappa);
      });
    }
  diagonal_ = Teuchos::rcp(new vector_type(s.owned_dof_map));
  auto view = diagonal_->getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (int i = 0; i < owned; ++i) {
    const Vec3 d = (P[i] * blocks[i] * P[i]).diagonal();
    for (int k = 0; k < 3; ++k) view(3 * i + k, 0) = d[k] + diagonal_mass_[i];
  }
}
}  // namespace

std::unique_ptr<HessianOperator> make_matrix_free_hessian(const NodeSpace& space) {
  return std::make_unique<MatrixFreeHessian>(space);
}

}  // namespace viscompm::linalg
