#include "viscompm/linalg/newton_system.hpp"

#include <MatrixMarket_Tpetra.hpp>
#include <algorithm>
#include <chrono>

#include "krylov.hpp"
#include "preconditioner.hpp"
#include "hessian_operator.hpp"
#include "matrix_market_io.hpp"

namespace viscompm::linalg {

struct NewtonSystem::Impl {
  Impl(const NodeSpace& s, const SolverConfiguration& c)
      : space(s),
        config(c),
        hessian(c.impl().settings.operator_form == OperatorForm::matrix_free ? make_matrix_free_hessian(s) : make_assembled_hessian(s)),
        preconditioner(make_preconditioner(c)),
        krylov(c) {}

  const NodeSpace& space;
  SolverConfiguration config;
  std::unique_ptr<HessianOperator> hessian;
  std::unique_ptr<Preconditioner> preconditioner;
  KrylovSolver krylov;
  bool pattern_changed = true;  // since the last preconditioner set-up
  bool preconditioned = false;  // for the current pattern
  std::uint64_t pattern_version = 0;
  NearNullspace modes;

  void build_near_nullspace();
  // Owned entries of a node field into a Tpetra vector on the owned dofs, and back.
  void to_owned(const NodeVectorField& field, multivector_type& owned) const;
  void from_owned(const multivector_type& owned, NodeVectorField& field) const;
};

void NewtonSystem::Impl::build_near_nullspace() {
  const auto& s = space.impl();
  const auto& partition = space.partition();
  modes.coordinates = Teuchos::rcp(new multivector_type(s.owned_node_map, 3));
  {
    auto xyz = modes.coordinates->getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < partition.owned_count(); ++i) {
      const Vec3 x = partition.geometry().node_position(partition.nodes()[i]);
      for (int d = 0; d < 3; ++d) xyz(i, d) = x[d];
    }
  }
  modes.rigid_body_modes = rigid_body_modes(*modes.coordinates, s.owned_dof_map);
  auto grid = std::make_shared<SystemGrid>();
  grid->dimensions = partition.geometry().nodes();
  for (std::size_t i = 0; i < partition.owned_count(); ++i)
    grid->owned_nodes.push_back(partition.geometry().node_index(partition.nodes()[i]));
  grid->owner = [&partition](const Int3& ijk) { return partition.grid_owner(ijk); };
  modes.grid = grid;
}

void NewtonSystem::Impl::to_owned(const NodeVectorField& field, multivector_type& owned) const {
  auto view = owned.getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (std::size_t i = 0; i < space.impl().owned_count; ++i)
    for (int c = 0; c < 3; ++c) view(3 * i + c, 0) = field[i][c];
}

void NewtonSystem::Impl::from_owned(const multivector_type& owned, NodeVectorField& field) const {
  field.assign(space.impl().local_count, Vec3::Zero());
  auto view = owned.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < space.impl().owned_count; ++i)
    for (int c = 0; c < 3; ++c) field[i][c] = view(3 * i + c, 0);
  space.import_ghosts(field);
}

NewtonSystem::NewtonSystem(const NodeSpace& space, const SolverConfiguration& config)
    : impl_(std::make_unique<Impl>(space, config)) {
  config.check_rank_count(space.comm().size());  // before any graph is built or system solved
  if (space.version() > 0) build_pattern();
}

NewtonSystem::~NewtonSystem() = default;

namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

void NewtonSystem::build_pattern() {
  Impl& m = *impl_;
  m.hessian->build_pattern();
  m.build_near_nullspace();
  m.pattern_version = m.space.version();
  m.pattern_changed = true;
  m.preconditioned = false;
}

double NewtonSystem::assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v,
                              bool project) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  m.hessian->update(potential, v, project);
  return seconds_since(start);
}

double NewtonSystem::precondition() {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  m.preconditioner->setup(*m.hessian, m.pattern_changed, m.modes);
  m.pattern_changed = false;
  m.preconditioned = true;
  return seconds_since(start);
}

bool NewtonSystem::preconditioned() const { return impl_->preconditioned; }

std::vector<std::int64_t> NewtonSystem::preconditioner_levels() const { return impl_->preconditioner->level_rows(); }

std::vector<std::tuple<long long, long long, double>> NewtonSystem::preconditioner_level_entries(int level) const {
  const auto A = impl_->preconditioner->level_matrix(level);
  std::vector<double> local;  // (row, column, value) triplets by global ids
  if (!A.is_null()) {
    const auto rows = A->getRowMap();
    const auto columns = A->getColMap();
    for (std::size_t r = 0; r < A->getNodeNumRows(); ++r) {
      crs_matrix_type::local_inds_host_view_type cols;
      crs_matrix_type::values_host_view_type vals;
      A->getLocalRowView(static_cast<local_ordinal_type>(r), cols, vals);
      for (std::size_t k = 0; k < cols.extent(0); ++k)
        local.insert(local.end(), {double(rows->getGlobalElement(static_cast<local_ordinal_type>(r))),
                                   double(columns->getGlobalElement(cols(k))), vals(k)});
    }
  }
  const auto all = impl_->space.comm().all_gather(local);
  std::vector<std::tuple<long long, long long, double>> entries;
  for (std::size_t k = 0; k + 2 < all.size(); k += 3)
    entries.emplace_back(static_cast<long long>(all[k]), static_cast<long long>(all[k + 1]), all[k + 2]);
  std::sort(entries.begin(), entries.end());
  return entries;
}

std::uint64_t NewtonSystem::pattern_version() const { return impl_->pattern_version; }

double NewtonSystem::default_tolerance() const { return impl_->krylov.default_tolerance(); }

LinearSolveReport NewtonSystem::solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance) {
  Impl& m = *impl_;
  const double setup_seconds = m.preconditioned ? 0.0 : precondition();
  const auto& s = m.space.impl();
  multivector_type b(s.owned_dof_map, 1), x(s.owned_dof_map, 1);
  m.to_owned(rhs, b);
  LinearSolveReport report = m.krylov.solve(m.hessian->op(), m.preconditioner->op(), x, b, tolerance);
  report.setup_seconds = setup_seconds;
  m.from_owned(x, dv);
  return report;
}

void NewtonSystem::apply_preconditioner(const NodeVectorField& r, NodeVectorField& z) {
  Impl& m = *impl_;
  if (!m.preconditioned) precondition();
  multivector_type R(m.space.impl().owned_dof_map, 1), Z(m.space.impl().owned_dof_map, 1);
  m.to_owned(r, R);
  const auto op = m.preconditioner->op();
  if (op.is_null()) Z.assign(R);
  else op->apply(R, Z);
  m.from_owned(Z, z);
}

bool NewtonSystem::has_preconditioner() const { return impl_->config.impl().settings.preconditioner != PreconditionerKind::none; }

void NewtonSystem::apply(const NodeVectorField& x, NodeVectorField& y) const {
  const Impl& m = *impl_;
  multivector_type X(m.space.impl().owned_dof_map, 1), Y(m.space.impl().owned_dof_map, 1);
  m.to_owned(x, X);
  m.hessian->op()->apply(X, Y);
  m.from_owned(Y, y);
}

std::int64_t NewtonSystem::global_rows() const {
  return static_cast<std::int64_t>(impl_->space.impl().owned_dof_map->getGlobalNumElements());
}

std::int64_t NewtonSystem::global_nonzeros() const { return impl_->hessian->nonzeros(); }
bool NewtonSystem::matrix_free() const { return impl_->hessian->matrix().is_null(); }
const SolverConfiguration& NewtonSystem::configuration() const { return impl_->config; }

std::vector<std::tuple<long long, long long, double>> NewtonSystem::gather_entries() const {
  const auto matrix = impl_->hessian->matrix();
  if (matrix.is_null()) throw std::logic_error("gather_entries: the operator is matrix-free");
  const auto& A = *matrix;
  const auto& comm = impl_->space.comm();
  // Local row and column dofs to grid dofs 3·(grid node id) + d (exact in doubles below 2^53).
  const auto& nodes = impl_->space.partition().nodes();
  auto grid_dof = [&](std::size_t local_dof) { return 3 * nodes[local_dof / 3] + static_cast<long long>(local_dof % 3); };
  std::vector<double> local;  // (row, column, value) triplets
  for (std::size_t r = 0; r < A.getNodeNumRows(); ++r) {
    typename crs_matrix_type::local_inds_host_view_type cols;
    typename crs_matrix_type::values_host_view_type vals;
    A.getLocalRowView(static_cast<local_ordinal_type>(r), cols, vals);
    for (std::size_t k = 0; k < cols.extent(0); ++k) {
      local.push_back(static_cast<double>(grid_dof(r)));
      local.push_back(static_cast<double>(grid_dof(static_cast<std::size_t>(cols(k)))));
      local.push_back(vals(k));
    }
  }
  const auto all = comm.all_gather(local);
  std::vector<std::tuple<long long, long long, double>> entries;
  for (std::size_t k = 0; k + 2 < all.size(); k += 3)
    entries.emplace_back(static_cast<long long>(all[k]), static_cast<long long>(all[k + 1]), all[k + 2]);
  std::sort(entries.begin(), entries.end());
  return entries;
}

void NewtonSystem::write_matrix_market(const std::string& prefix, const NodeVectorField& rhs) const {
  const Impl& m = *impl_;
  const auto matrix = m.hessian->matrix();
  if (matrix.is_null()) throw std::logic_error("write_matrix_market: the operator is matrix-free");
  multivector_type b(m.space.impl().owned_dof_map, 1);
  m.to_owned(rhs, b);
  write_contiguous_matrix_market(*matrix, b, *m.modes.coordinates, prefix);
}

double NewtonSystem::time_apply(int repetitions) const {
  const Impl& m = *impl_;
  multivector_type X(m.space.impl().owned_dof_map, 1), Y(m.space.impl().owned_dof_map, 1);
  X.randomize();
  m.hessian->op()->apply(X, Y);  // warm-up
  m.space.comm().barrier();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < repetitions; ++k) m.hessian->op()->apply(X, Y);
  m.space.comm().barrier();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repetitions;
}

}  // namespace viscompm::linalg
