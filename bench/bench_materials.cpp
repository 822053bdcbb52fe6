// Per-particle cost of each constitutive model: Material::evaluate at order 0 (energy), 1 (energy
// and gradient) and 2 (energy, gradient and Hessian), and update_state, at random feasible states.
// Not a test: prints a table (doc/performance.md, "Constitutive models").
//
//   cmake --build build --target bench_materials && build/bin/bench_materials [particles] [repetitions]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "model_variants.hpp"  // test/support
#include "viscompm/materials/registry.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
// The variants the derivative tests check, at the sponge's moduli (Table 5.2: μ = 360, λ = 1400).
std::vector<testkit::ModelVariant> variants() { return testkit::model_variants(100.0); }

std::unique_ptr<Material> build(const testkit::ModelVariant& v) { return testkit::build_material(v, "bench"); }

Mat3 random_matrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Mat3 m;
  for (int i = 0; i < 9; ++i) m.data()[i] = u(rng);
  return m;
}

Mat3 random_deformation(std::mt19937& rng, double spread) {
  Mat3 F;
  do F = Mat3::Identity() + random_matrix(rng, spread);
  while (F.determinant() < 0.5);
  return F;
}

// Seconds per particle for `work` over all particles, the best of `repetitions` sweeps.
template <class Work>
double best_seconds_per_particle(std::size_t n, int repetitions, Work&& work) {
  double best = 1e30;
  for (int r = 0; r < repetitions; ++r) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t p = 0; p < n; ++p) work(p);
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count() / static_cast<double>(n));
  }
  return best;
}
}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 4096;
  const int repetitions = argc > 2 ? std::atoi(argv[2]) : 50;
  std::mt19937 rng(20151127);
  particles::ParticleSet particles;
  std::vector<Mat3> increments;
  for (std::size_t p = 0; p < n; ++p) {
    particles.add(static_cast<ParticleId>(p), Vec3::Zero(), Vec3::Zero(), 1.0, 1e-3, 0);
    particles.deformation_gradient[p] = random_deformation(rng, 0.3);
    const Mat3 r = random_deformation(rng, 0.3);
    particles.left_cauchy_green_ob[p] = r * r.transpose();
    particles.elastic_deformation_gradient[p] = random_deformation(rng, 0.2);
    particles.plastic_deformation_gradient[p] =
        particles.elastic_deformation_gradient[p].inverse() * particles.deformation_gradient[p];
    increments.push_back(random_matrix(rng, 0.02));
  }
  const StepContext step{1e-3};
  std::printf("%zu particles, best of %d sweeps, nanoseconds per particle\n", n, repetitions);
  std::printf("| model | energy (order 0) | + gradient (order 1) | + Hessian (order 2) | update_state |\n");
  std::printf("|---|---|---|---|---|\n");
  double checksum = 0.0;
  for (const auto& v : variants()) {
    const auto material = build(v);
    double t[3];
    for (int order = 0; order <= 2; ++order) {
      PotentialDerivatives out;
      t[order] = best_seconds_per_particle(n, repetitions, [&](std::size_t p) {
        if (material->evaluate(particles, p, increments[p], step, order, out))
          checksum += out.energy + out.gradient(0, 0) + out.hessian(4, 4);
      });
    }
    // update_state on a copy, restored before each sweep would cost more than it measures: the
    // states drift by one small step per sweep, which keeps them feasible.
    particles::ParticleSet copy = particles;
    const double u = best_seconds_per_particle(n, std::max(1, repetitions / 5), [&](std::size_t p) {
      material->update_state(copy, p, increments[p], step);
    });
    checksum += copy.deformation_gradient[0](0, 0);
    std::printf("| %s | %.0f | %.0f | %.0f | %.0f |\n", v.label.c_str(), t[0] * 1e9, t[1] * 1e9, t[2] * 1e9, u * 1e9);
  }
  std::printf("(checksum %g)\n", checksum);
  return 0;
}
