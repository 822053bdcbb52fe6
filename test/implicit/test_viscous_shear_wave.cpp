// Viscosity convention (doc/numerics.md). A shear wave v_x = V cos(k (y − y0)), k = π/H, in a free
// slab of purely viscous material (its faces y0 and y0 + H are traction free for this mode)
// decays as e^{−ν k² t}, ν = η/ρ. With the physical convention the rate depends on Δt only
// through the first-order time error of the implicit step (backward Euler's discrete rate is
// ln(1 + ν k² Δt)/Δt). With the paper's (5.11) the same parameter acts as the viscosity μ^N/Δt.
// (A wave between sticky plates would also carry the O(Δx) error of where MPM puts a wall.)
#include <gtest/gtest.h>

#include <cmath>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
constexpr double density = 1.0, viscosity = 0.05, height = 0.4, y0 = 0.3, amplitude = 0.01, duration = 0.15;
const double k = M_PI / height;

// Amplitude of the cos(k (y − y0)) mode of v_x over the particles in the middle of the slab (away
// from its ends in x), by least squares.
double mode_amplitude(simulation::Simulation& sim, const parallel::Communicator& comm) {
  double num = 0.0, den = 0.0;
  const auto& ps = sim.particles();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    if (std::abs(ps.position[p].x() - 0.8) > 0.2) continue;
    const double c = std::cos(k * (ps.position[p].y() - y0));
    num += c * ps.velocity[p].x();
    den += c * c;
  }
  return comm.sum(num) / comm.sum(den);
}

// The decay rate of the wave measured over `duration` with steps of dt.
double measured_rate(const std::string& convention, double parameter, double dt) {
  auto scene = testkit::base_scene(Vec3(1.6, 1.0, 0.3), 0.05);
  scene.materials.push_back(testkit::oldroyd_b_material("fluid", density, 0.0, 0.0, parameter, convention, 1.0));
  scene.bodies.push_back(testkit::box_body("fluid", Vec3(0.2, y0, 0.1), Vec3(1.4, y0 + height, 0.2), Vec3::Zero()));
  scene.simulation.max_time_step = dt;
  scene.newton.tolerance = 1e-10;
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-12), comm);
  auto& ps = sim.particles();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const double phase = k * (ps.position[p].y() - y0);
    ps.velocity[p] = Vec3(amplitude * std::cos(phase), 0.0, 0.0);
    Mat3 C = Mat3::Zero();
    C(0, 1) = -amplitude * k * std::sin(phase);  // APIC carries the local velocity gradient
    ps.affine_velocity[p] = C;
  }
  const double a0 = mode_amplitude(sim, comm);
  simulation::RunSummary summary;
  sim.advance_to(duration, summary);
  EXPECT_EQ(summary.steps, std::lround(duration / dt));
  return -std::log(mode_amplitude(sim, comm) / a0) / duration;
}

// Backward Euler's decay rate for a mode with continuous rate λ.
double backward_euler_rate(double lambda, double dt) { return std::log1p(lambda * dt) / dt; }
}  // namespace

TEST(ViscousShearWave, PhysicalConventionDecaysAtNuKSquaredIndependentOfTimeStep) {
  const double lambda = viscosity / density * k * k;
  const double coarse = measured_rate("physical", viscosity, 0.02);
  const double fine = measured_rate("physical", viscosity, 0.005);
  // The rate converges to ν k² as Δt → 0 (first order in Δt, like backward Euler) ...
  EXPECT_NEAR(fine, lambda, 0.03 * lambda);
  EXPECT_NEAR(coarse, lambda, 0.08 * lambda);
  EXPECT_LT(std::abs(fine - lambda), std::abs(coarse - lambda));
  // ... and a 4x larger Δt changes it by a few percent, not by the factor 4 of the paper's μ^N.
  EXPECT_NEAR(coarse / fine, 1.0, 0.06);
}

TEST(ViscousShearWave, PaperConventionActsAsViscosityMuNOverDt) {
  // The same μ^N at Δt and Δt/2: the effective viscosity μ^N/Δt, hence the rate, doubles.
  const double mu_n = viscosity * 0.01;
  const double at_dt = measured_rate("paper", mu_n, 0.01);
  const double at_half_dt = measured_rate("paper", mu_n, 0.005);
  const double lambda_dt = (mu_n / 0.01) / density * k * k, lambda_half = (mu_n / 0.005) / density * k * k;
  EXPECT_NEAR(at_dt, backward_euler_rate(lambda_dt, 0.01), 0.05 * lambda_dt);
  EXPECT_NEAR(at_half_dt, backward_euler_rate(lambda_half, 0.005), 0.05 * lambda_half);
  EXPECT_NEAR(at_half_dt / at_dt, 2.0, 0.15);
}
