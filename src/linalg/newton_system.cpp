#include "viscompm/linalg/newton_system.hpp"

#include <MatrixMarket_Tpetra.hpp>
#include <Tpetra_BlockCrsMatrix.hpp>
#include <Tpetra_BlockCrsMatrix_Helpers.hpp>
#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>

#include "deflation.hpp"
#include "krylov.hpp"
#include "viscompm/implicit/stiff_bodies.hpp"
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
  std::uint64_t pattern_version = 0;               // the NodeSpace version of H's pattern
  std::optional<std::uint64_t> preconditioned_for;  // the pattern of the last preconditioner set-up
  NearNullspace modes;
  Teuchos::RCP<crs_matrix_type> stiff_modes;            // Deflation: Z of the last assembly (null: none)
  Teuchos::RCP<DeflatedPreconditioner> deflated;        // the preconditioner with Z deflated
  int stiff_bodies = 0;
  bool last_assembly_projected = false;  // whether the last assembly projected H to PSD

  /// The operator CG is preconditioned with (null: none).
  Teuchos::RCP<operator_type> preconditioner_op() const {
    return deflated.is_null() ? preconditioner->op() : Teuchos::rcp_implicit_cast<operator_type>(deflated);
  }
  /// Z: the rigid modes of the stiff bodies of `potential` on the owned dofs, projected by the
  /// constraints (null when there is no stiff body).
  void build_stiff_modes(const implicit::IncrementalPotential& potential);

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

void NewtonSystem::Impl::build_stiff_modes(const implicit::IncrementalPotential& potential) {
  const SolverSettings& settings = config.impl().settings;
  const implicit::StiffBodies bodies =
      implicit::find_stiff_bodies(potential, settings.stiff_cfl, settings.max_stiff_bodies, space.comm());
  stiff_bodies = bodies.count;
  if (bodies.count == 0) {
    stiff_modes = Teuchos::null;
    return;
  }
  const auto& partition = space.partition();
  const std::size_t owned = space.impl().owned_count;
  const int k = 6 * bodies.count;
  // Six modes per body: translations and rotations about its centroid (a body moves rigidly to
  // first order, the stiff elastic energy barely resists these modes and a local smoother cannot
  // reach them: they are the slow components CG is left with). Z is n × k and sparse: a dof row
  // holds the 6 columns of each body whose cells reach its node (node_bodies, sorted by node).
  using row_offsets_type = crs_matrix_type::local_graph_device_type::row_map_type::non_const_type;
  using columns_type = crs_matrix_type::local_graph_device_type::entries_type::non_const_type;
  using values_type = crs_matrix_type::local_matrix_device_type::values_type;
  std::vector<int> bodies_of(owned + 1, 0);  // prefix counts of each owned node's bodies
  for (const auto& [node, body] : bodies.node_bodies)
    if (static_cast<std::size_t>(node) < owned) ++bodies_of[node + 1];
  for (std::size_t i = 0; i < owned; ++i) bodies_of[i + 1] += bodies_of[i];
  row_offsets_type offsets("viscompm stiff modes offsets", 3 * owned + 1);
  for (std::size_t i = 0; i < owned; ++i)
    for (int d = 0; d < 3; ++d) offsets(3 * i + d) = 6 * (3 * bodies_of[i] + d * (bodies_of[i + 1] - bodies_of[i]));
  offsets(3 * owned) = 18 * static_cast<std::size_t>(bodies_of[owned]);
  const std::size_t entries = offsets(3 * owned);
  columns_type columns("viscompm stiff modes columns", entries);
  values_type values("viscompm stiff modes values", entries);
  const auto& projection = potential.constraints().projection;
  std::vector<int> filled(owned, 0);  // bodies of a node written so far
  for (const auto& [node, body] : bodies.node_bodies) {
    if (static_cast<std::size_t>(node) >= owned) continue;
    const Vec3 r = partition.geometry().node_position(partition.nodes()[node]) - bodies.centroids[body];
    const Mat3& P = projection[node];
    // Translations e_d and rotations e_a × r, each through the node's constraint projection.
    Mat3 rotations;
    rotations << 0.0, r.z(), -r.y(), -r.z(), 0.0, r.x(), r.y(), -r.x(), 0.0;  // column a: e_a × r
    const Mat3 rotation_columns = P * rotations;
    const int slot = filled[node]++;
    for (int d = 0; d < 3; ++d) {
      std::size_t at = offsets(3 * node + d) + 6 * slot;
      for (int a = 0; a < 3; ++a) {
        columns(at + a) = 6 * body + a;
        values(at + a) = P(d, a);
        columns(at + 3 + a) = 6 * body + 3 + a;
        values(at + 3 + a) = rotation_columns(d, a);
      }
    }
  }
  // Columns: the k modes, all on every rank (local index = mode); their domain on rank 0.
  const auto comm = space.impl().owned_dof_map->getComm();
  Teuchos::Array<global_ordinal_type> all(k);
  for (int a = 0; a < k; ++a) all[a] = a;
  const auto column_map = Teuchos::rcp(new map_type(Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid(), all(), 0, comm));
  const auto domain_map = Teuchos::rcp(new map_type(k, comm->getRank() == 0 ? k : 0, 0, comm));
  stiff_modes = Teuchos::rcp(new crs_matrix_type(space.impl().owned_dof_map, column_map, offsets, columns, values));
  stiff_modes->expertStaticFillComplete(domain_map, space.impl().owned_dof_map,
                                        Teuchos::rcp(new import_type(domain_map, column_map)));
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
}

double NewtonSystem::prepare() {
  if (impl_->pattern_version == impl_->space.version()) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  build_pattern();
  return seconds_since(start);
}

double NewtonSystem::assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v,
                              bool project) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  m.hessian->update(potential, v, project);
  m.last_assembly_projected = project;
  if (m.config.impl().settings.deflation == Deflation::stiff_bodies) m.build_stiff_modes(potential);
  return seconds_since(start);
}

double NewtonSystem::precondition() {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  m.preconditioner->setup(*m.hessian, m.preconditioned_for != m.pattern_version, m.modes);
  m.deflated = m.stiff_modes.is_null()
                   ? Teuchos::null
                   : Teuchos::rcp(new DeflatedPreconditioner(*m.hessian->op(), m.hessian->matrix(),
                                                             m.preconditioner->op(), *m.stiff_modes));
  m.preconditioned_for = m.pattern_version;
  return seconds_since(start);
}

bool NewtonSystem::preconditioned() const { return impl_->preconditioned_for == impl_->pattern_version; }

void NewtonSystem::require_preconditioner(const char* caller) const {
  if (!preconditioned())
    throw std::logic_error(std::string("NewtonSystem::") + caller +
                           ": the preconditioner was not set up for the current pattern (call precondition() first)");
}

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

LinearSolveReport NewtonSystem::solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance,
                                      int max_iterations) {
  Impl& m = *impl_;
  require_preconditioner("solve");
  const auto& s = m.space.impl();
  multivector_type b(s.owned_dof_map, 1), x(s.owned_dof_map, 1);
  m.to_owned(rhs, b);
  LinearSolveReport report = m.krylov.solve(m.hessian->op(), m.preconditioner_op(), x, b, tolerance, max_iterations);
  m.from_owned(x, dv);
  return report;
}

void NewtonSystem::apply_preconditioner(const NodeVectorField& r, NodeVectorField& z) {
  Impl& m = *impl_;
  require_preconditioner("apply_preconditioner");
  multivector_type R(m.space.impl().owned_dof_map, 1), Z(m.space.impl().owned_dof_map, 1);
  m.to_owned(r, R);
  const auto op = m.preconditioner_op();
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

void NewtonSystem::write_matrix_market(const std::string& prefix, const implicit::IncrementalPotential& potential,
                                       const NodeVectorField& v, const NodeVectorField& rhs) const {
  const Impl& m = *impl_;
  auto matrix = m.hessian->matrix();
  std::unique_ptr<HessianOperator> assembled;  // the matrix-free operator's H, for the file only
  if (matrix.is_null()) {
    assembled = make_assembled_hessian(m.space);
    assembled->build_pattern();
    assembled->update(potential, v, m.last_assembly_projected);
    matrix = assembled->matrix();
  }
  multivector_type b(m.space.impl().owned_dof_map, 1);
  m.to_owned(rhs, b);
  write_contiguous_matrix_market(*matrix, b, *m.modes.coordinates, prefix);
}

namespace {
// Seconds per application of `op` to a random vector (mean of `repetitions`, after one warm-up;
// the ranks start and stop together).
template <class Communicator>
double mean_apply_seconds(const operator_type& op, const Communicator& comm, int repetitions) {
  multivector_type X(op.getDomainMap(), 1), Y(op.getRangeMap(), 1);
  X.randomize();
  op.apply(X, Y);  // warm-up
  comm.barrier();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < repetitions; ++k) op.apply(X, Y);
  comm.barrier();
  return seconds_since(start) / repetitions;
}
}  // namespace

double NewtonSystem::time_apply(int repetitions) const {
  return mean_apply_seconds(*impl_->hessian->op(), impl_->space.comm(), repetitions);
}

double NewtonSystem::time_block_apply(int repetitions, double& convert_seconds) const {
  const Impl& m = *impl_;
  const auto matrix = m.hessian->matrix();
  if (matrix.is_null()) throw std::logic_error("NewtonSystem::time_block_apply: the operator is matrix-free");
  m.space.comm().barrier();
  const auto start = std::chrono::steady_clock::now();
  const auto blocks = Tpetra::convertToBlockCrsMatrix(*matrix, 3);
  m.space.comm().barrier();
  convert_seconds = seconds_since(start);
  return mean_apply_seconds(*blocks, m.space.comm(), repetitions);
}

double NewtonSystem::time_preconditioner(int repetitions) const {
  const Impl& m = *impl_;
  require_preconditioner("time_preconditioner");
  const auto op = m.preconditioner_op();
  return op.is_null() ? 0.0 : mean_apply_seconds(*op, m.space.comm(), repetitions);
}

}  // namespace viscompm::linalg
