// Figure 5.4: "The Weissenberg number controls the damping of the left elastic Cauchy-Green strain
// to the identity. The smaller the Weissenberg, the more plastic the flow." The same scene — a free
// block of the Chapter 5 fluid thrown into an isochoric stretch v = ε̇ (x − x_c, −(y − y_c), 0),
// slowed by its elasticity and a little viscosity — at three Weissenberg numbers. Its elastic
// recovery R = (s_max − s_end)/(s_max − 1), with s the block's stretch along x (the root mean
// square of x − x̄ relative to its initial value), measured from the particles, must fall
// monotonically with Wi: an elastic block springs back (R → 1), a fluid one keeps its shape.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
constexpr double stretch_rate = 12.0, duration = 1.0;

// Root mean square of x − x̄ over all particles.
double spread_x(const particles::ParticleSet& ps, const parallel::Communicator& comm) {
  double n = 0.0, sx = 0.0, sxx = 0.0;
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const double x = ps.position[p].x();
    n += 1.0;
    sx += x;
    sxx += x * x;
  }
  n = comm.sum(n), sx = comm.sum(sx), sxx = comm.sum(sxx);
  return std::sqrt(sxx / n - (sx / n) * (sx / n));
}

struct Recovery {
  double peak = 0.0, end = 0.0;  ///< s_max and s(T)
  double value() const { return (peak - end) / (peak - 1.0); }
};

Recovery measure_recovery(double weissenberg) {
  auto scene = testkit::base_scene(Vec3(1.4, 1.0, 0.4), 0.05);
  scene.materials.push_back(testkit::oldroyd_b_material("goo", 1.0, 10.0, 50.0, 0.1, "physical", weissenberg));
  const Vec3 lo(0.5, 0.4, 0.15), hi(0.9, 0.6, 0.25), center = 0.5 * (lo + hi);
  scene.bodies.push_back(testkit::box_body("goo", lo, hi, Vec3::Zero()));
  scene.simulation.max_time_step = 5e-3;
  scene.newton.tolerance = 1e-8;
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), comm);
  auto& ps = sim.particles();
  const Mat3 L = Vec3(stretch_rate, -stretch_rate, 0.0).asDiagonal();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    ps.velocity[p] = L * (ps.position[p] - center);
    ps.affine_velocity[p] = L;  // APIC carries the velocity gradient
  }
  const double s0 = spread_x(ps, comm);
  Recovery r;
  simulation::RunSummary summary;
  for (int k = 1; k <= 50; ++k) {
    sim.advance_to(k * duration / 50, summary);
    r.peak = std::max(r.peak, spread_x(ps, comm) / s0);
  }
  r.end = spread_x(ps, comm) / s0;
  return r;
}
}  // namespace

TEST(WeissenbergSweep, ElasticRecoveryFallsMonotonicallyWithTheWeissenbergNumber) {
  const std::vector<double> weissenberg = {10.0, 0.05, 0.005};
  std::vector<Recovery> recovery;
  for (double wi : weissenberg) recovery.push_back(measure_recovery(wi));
  const parallel::Communicator comm(MPI_COMM_WORLD);
  for (std::size_t k = 0; k < weissenberg.size(); ++k) {
    if (comm.is_root())
      std::cout << "Wi = " << weissenberg[k] << ": peak stretch " << recovery[k].peak << ", final "
                << recovery[k].end << ", recovery " << recovery[k].value() << "\n";
    EXPECT_GT(recovery[k].peak, 1.15) << "the block must be stretched substantially at Wi = " << weissenberg[k];
  }
  for (std::size_t k = 1; k < weissenberg.size(); ++k)
    EXPECT_LT(recovery[k].value(), recovery[k - 1].value() - 0.1) << "Wi " << weissenberg[k - 1] << " → " << weissenberg[k];
  // The ends of the sweep: a nearly elastic block recovers most of its stretch, a nearly viscous
  // one almost none of it.
  EXPECT_GT(recovery.front().value(), 0.8);
  EXPECT_LT(recovery.back().value(), 0.2);
}
