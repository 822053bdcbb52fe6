// Von Mises plasticity (§4.2.6, §4.3) with isotropic linear hardening Y(ε) = Y + K ε:
//   energy:  ψ_NH(F̂_E) of (5.8) for the elastic predictor F̂_E = (I + A) F_E^n (5.12);
//   update:  the radial return mapping of Simo (1988) / Simo & Hughes (Box 9.1) on the deviatoric
//            Kirchhoff stress τ' = μ dev(b^E) of (5.9):
//              f = (3/2 τ':τ')^{1/2} − Y(ε) of §4.2.6 at the trial b^E_tr = F̂_E F̂_E^T;
//              if f > 0: μ̄ = μ tr(b^E_tr)/3, Δγ = (‖τ'_tr‖ − √(2/3) Y(ε)) / (2μ̄ + 2K/3),
//                        τ' = τ'_tr − 2μ̄ Δγ n, ε += √(2/3) Δγ (so f = 0 after the return),
//                        b^E = τ'/μ + m I with m such that det b^E = det b^E_tr: the flow is
//                        isochoric (§4.3), J_P stays 1;
//              F_E = (b^E)^{1/2} R_tr with the rotation of the predictor, F_P = F_E^{-1} F.
// As for svd_plasticity, the return mapping acts after the solve (the approach §5.4.2 points to).
#pragma once

#include "viscompm/materials/material.hpp"
#include "viscompm/materials/neo_hookean.hpp"
#include "viscompm/materials/shared_parameters.hpp"

namespace viscompm::materials {

struct VonMisesParameters : ElasticParameters {
  double yield_stress = 1.0;       ///< Y of §4.2.6
  double hardening_modulus = 0.0;  ///< K of Y(ε) = Y + K ε

  static const ParameterTable<VonMisesParameters>& table();
};

namespace von_mises {

/// The yield function f(τ, ε) = (3/2 τ':τ')^{1/2} − (Y + K ε) of §4.2.6 for b^E [Pa].
double yield_function(const VonMisesParameters& parameters, const Mat3& b_elastic, double plastic_strain);

struct ReturnMapping {
  Mat3 elastic_deformation_gradient;
  double plastic_strain_increment = 0.0;  ///< √(2/3) Δγ
  double trial_yield_function = 0.0;      ///< f at the trial state [Pa]
};
/// The return mapping above for a trial elastic deformation gradient.
ReturnMapping return_mapping(const VonMisesParameters& parameters, const Mat3& trial_F_E, double plastic_strain);

}  // namespace von_mises

class VonMises : public Material {
 public:
  VonMises(std::string name, const VonMisesParameters& parameters);

  std::string model() const override { return "von_mises"; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  std::vector<std::string> state_fields() const override {
    return {"deformation_gradient", "elastic_deformation_gradient", "plastic_deformation_gradient", "yield_function",
            "equivalent_plastic_strain"};
  }
  const VonMisesParameters& parameters() const { return parameters_; }

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  /// F, the elastic predictor and its return mapping; the yield function is the trial one [Pa].
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  VonMisesParameters parameters_;
};

}  // namespace viscompm::materials
