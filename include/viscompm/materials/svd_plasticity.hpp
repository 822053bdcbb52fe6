// Plasticity by clamping the singular values of F_E (§4.4, after Stomakhin et al. 2013), with the
// hardening of §4.5.1 (ζ > 0) or the softening of §4.5.2 (ζ < 0):
//   energy:  ψ_NH(F̂_E; μ(F_P), λ(F_P)) of the elastic predictor F̂_E = (I + A) F_E^n (5.12),
//            μ = μ0 e^{ζ(1 − J_P)}, λ = λ0 e^{ζ(1 − J_P)}, J_P = det F_P^n  (§4.5.1)
//   update:  F ← (I + A) F; F_E = U Σ V^T ← U clamp_{[1−c, 1+s]}(Σ) V^T; F_P ← V Σ̂^{-1} U^T F (§4.4).
// The clamp is a return mapping applied after the solve, as in the method §4.4 cites: the Newton
// energy is the elastic predictor's, with the plastic state of time n.
#pragma once

#include "viscompm/materials/material.hpp"
#include "viscompm/materials/neo_hookean.hpp"
#include "viscompm/materials/shared_parameters.hpp"

namespace viscompm::materials {

struct SvdPlasticityParameters : ElasticParameters {
  double critical_compression = 2.5e-2;  ///< c of §4.4
  double critical_stretch = 7.5e-3;      ///< s of §4.4
  double hardening = 10.0;               ///< ζ of §4.5

  static const ParameterTable<SvdPlasticityParameters>& table();
};

namespace svd_plasticity {

/// μ, λ of §4.5.1 for a plastic Jacobian J_P.
neo_hookean::Lame hardened_lame(const SvdPlasticityParameters& parameters, double plastic_jacobian);

}  // namespace svd_plasticity

class SvdPlasticity : public Material {
 public:
  SvdPlasticity(std::string name, const SvdPlasticityParameters& parameters);

  std::string model() const override { return "svd_plasticity"; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  std::vector<std::string> state_fields() const override {
    return {"deformation_gradient", "elastic_deformation_gradient", "plastic_deformation_gradient", "yield_function"};
  }
  /// μ and λ of particle p (§4.5.1), from its stored F_P.
  neo_hookean::Lame lame(const particles::ParticleSet& particles, std::size_t p) const;

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  /// F, the elastic predictor, the clamp of §4.4 and F_P; the yield function is how far the
  /// predictor's singular values lie outside [1 − c, 1 + s] (> 0: clamped this step).
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  SvdPlasticityParameters parameters_;
};

}  // namespace viscompm::materials
