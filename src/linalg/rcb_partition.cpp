// Zoltan2 lives in this translation unit only (its headers are slow to compile).
#include "viscompm/linalg/rcb_partition.hpp"

#include <Teuchos_DefaultMpiComm.hpp>
#include <Zoltan2_BasicVectorAdapter.hpp>
#include <Zoltan2_PartitioningProblem.hpp>
#include <limits>

namespace viscompm::linalg {

std::unique_ptr<parallel::BoxDecomposition> make_rcb_decomposition(const parallel::Communicator& comm,
                                                                   const grid::GridGeometry& geometry,
                                                                   const particles::ParticleSet& particles) {
  using types = Zoltan2::BasicUserTypes<double, int, long long>;
  using adapter_type = Zoltan2::BasicVectorAdapter<types>;
  const std::size_t n = particles.size();
  std::vector<double> x(n), y(n), z(n);
  std::vector<long long> ids(particles.id.begin(), particles.id.end());
  for (std::size_t p = 0; p < n; ++p) {
    x[p] = particles.position[p].x();
    y[p] = particles.position[p].y();
    z[p] = particles.position[p].z();
  }
  adapter_type adapter(static_cast<int>(n), ids.data(), x.data(), y.data(), z.data());
  Teuchos::ParameterList params;
  // Zoltan2's multi-jagged algorithm run as RCB keeps its part boxes (its "rcb" does not).
  params.set("algorithm", "multijagged");
  params.set("mj_enable_rcb", true);
  params.set("num_global_parts", comm.size());
  params.set("rectilinear", true);
  params.set("imbalance_tolerance", 1.05);
  const auto tcomm = Teuchos::rcp(new Teuchos::MpiComm<int>(comm.comm()));
  Zoltan2::PartitioningProblem<adapter_type> problem(&adapter, &params, tcomm);
  problem.solve();
  // Each part's box: the bounding box of the particles Zoltan2 put in it. (Rectilinear cuts keep
  // these boxes disjoint; space between them goes to the nearest box. Zoltan2 13.2's own
  // getPartBoxesView returns a reference to a temporary, so it cannot be used.)
  const auto* parts = problem.getSolution().getPartListView();
  const int ranks = comm.size();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> lower(3 * ranks, inf), upper(3 * ranks, -inf);
  for (std::size_t p = 0; p < n; ++p)
    for (int d = 0; d < 3; ++d) {
      lower[3 * parts[p] + d] = std::min(lower[3 * parts[p] + d], particles.position[p][d]);
      upper[3 * parts[p] + d] = std::max(upper[3 * parts[p] + d], particles.position[p][d]);
    }
  MPI_Allreduce(MPI_IN_PLACE, lower.data(), 3 * ranks, MPI_DOUBLE, MPI_MIN, comm.comm());
  MPI_Allreduce(MPI_IN_PLACE, upper.data(), 3 * ranks, MPI_DOUBLE, MPI_MAX, comm.comm());
  std::vector<parallel::BoxDecomposition::Box> result(ranks);
  for (int r = 0; r < ranks; ++r)
    result[r] = {Vec3(lower[3 * r], lower[3 * r + 1], lower[3 * r + 2]),
                 Vec3(upper[3 * r], upper[3 * r + 1], upper[3 * r + 2])};
  return std::make_unique<parallel::BoxDecomposition>(geometry, std::move(result));
}

}  // namespace viscompm::linalg
