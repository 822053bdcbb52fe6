// Compressible Neo-Hookean elasticity (§2.5.4) in the form of (5.8) with b = F F^T:
//   ψ(F) = μ/2 (tr(F F^T) − 3) − μ ln J + λ/2 (J − 1)²,  J = det F.
// (§2.5.4 prints the last term as λ/2 det(F)², which does not vanish with its gradient at F = I;
// (5.8)'s (J − 1)² does, and is what every elastic model here uses.) The free functions are the
// energy of a deformation gradient — F of the neo_hookean model, the elastic predictor F_E of
// svd_plasticity and von_mises — and its derivatives; evaluate_potential chains them to A through
// F̂ = (I + A) G (5.12).
#pragma once

#include "viscompm/core/parameters.hpp"
#include "viscompm/materials/shared_parameters.hpp"
#include "viscompm/materials/material.hpp"

namespace viscompm::materials {

namespace neo_hookean {

struct Lame {
  double mu = 0.0;      ///< μ
  double lambda = 0.0;  ///< λ
};

/// ψ(F); F must have det F > 0.
double energy_density(const Lame& lame, const Mat3& F);
/// P = ∂ψ/∂F = μ (F − F^{-T}) + λ J (J − 1) F^{-T}.
Mat3 first_piola(const Lame& lame, const Mat3& F);
/// ∂²ψ/∂vec(F)².
Mat9 energy_hessian(const Lame& lame, const Mat3& F);
/// Kirchhoff stress τ = P F^T = μ (F F^T − I) + λ J (J − 1) I (J times (5.9)).
Mat3 kirchhoff_stress(const Lame& lame, const Mat3& F);

/// Φ = V ψ((I + A) G) and its derivatives in A (order 0, 1, 2); false if det((I + A) G) ≤ 0.
bool evaluate_potential(const Lame& lame, const Mat3& G, const Mat3& A, double volume, int order,
                        PotentialDerivatives& out);

}  // namespace neo_hookean

struct NeoHookeanParameters : ElasticParameters {
  static const ParameterTable<NeoHookeanParameters>& table();
};

class NeoHookean : public Material {
 public:
  NeoHookean(std::string name, const NeoHookeanParameters& parameters);

  std::string model() const override { return "neo_hookean"; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  std::vector<std::string> state_fields() const override { return {"deformation_gradient"}; }

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  NeoHookeanParameters parameters_;
};

}  // namespace viscompm::materials
