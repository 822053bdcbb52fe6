// The Herschel–Bulkley-like fluid of §4.6.2 (Bingham for h = 1, §4.2.4; shear thinning for h < 1
// and thickening for h > 1, §4.2.5): the Chapter 5 energy (5.8) of b^E = (J/J_HB)^{2/3} b_HB with
// the Newtonian potential (5.11) (on ε̂ or on dev ε̂: "Viscous strain", as oldroyd_b), b_HB updated
// by the positive-definite scheme
//   (1 + a) b_HB^{n+1} = (I + A) b_HB^n (I + A)^T + a (tr b_HB^n / 3) I,
//   a = (2Δt/3) tr(b̂) max(0, (‖dev b̂‖ − σ_Y)/η)^{1/h} / ‖dev b̂‖,
// with the flow rule evaluated on the unimodular b̂ = b_HB / det(b_HB)^{1/3} (the b̂_e of §4.2.4,
// which is J^{-2/3} b^E). The thesis writes §4.6.2 with b_HB itself; doc/materials.md explains
// why that has no steady shear flow and why b̂ is used instead. a depends on time-n quantities
// only, so Ŝ(A) is quadratic in A and the energy is minimised over exactly the stored update.
#pragma once

#include "viscompm/materials/material.hpp"
#include "viscompm/materials/shared_parameters.hpp"
#include "viscompm/materials/strain_maps.hpp"

namespace viscompm::materials {

struct HerschelBulkleyParameters : ElasticParameters, NewtonianParameters {
  double yield_stress = 0.1;       ///< σ_Y of §4.6.2, a threshold on ‖dev b̂‖ (in units of μ)
  double plastic_viscosity = 1.0;  ///< η of §4.6.2
  double flow_index = 1.0;         ///< h of §4.2.5 (1: Bingham)

  /// The herschel_bulkley model's parameters.
  static const ParameterTable<HerschelBulkleyParameters>& table();
  /// The bingham model's: the same without Flow index (h = 1).
  static const ParameterTable<HerschelBulkleyParameters>& bingham_table();
};

namespace herschel_bulkley {

/// The unimodular part b / det(b)^{1/3} of an SPD matrix.
Mat3 unimodular(const Mat3& b);

/// The flow rule at a strain b_HB, evaluated on b̂ = unimodular(b_HB).
struct FlowRule {
  double trace = 3.0;            ///< tr b̂
  double deviatoric_norm = 0.0;  ///< ‖dev b̂‖
  double yield_function = 0.0;   ///< ‖dev b̂‖ − σ_Y (> 0: plastic flow)
  double plastic_rate = 0.0;     ///< max(0, (‖dev b̂‖ − σ_Y)/η)^{1/h} of §4.2.5 [1/s]
  /// The coefficient a of the update above for a step of size dt.
  double plastic_coefficient(double dt) const;
};
FlowRule flow_rule(const HerschelBulkleyParameters& parameters, const Mat3& b_hb);

}  // namespace herschel_bulkley

class HerschelBulkley : public Material {
 public:
  /// `model` is the registry name ("herschel_bulkley" or "bingham").
  HerschelBulkley(std::string name, const HerschelBulkleyParameters& parameters, std::string model = "herschel_bulkley");

  std::string model() const override { return model_; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  std::vector<std::string> state_fields() const override {
    return {"deformation_gradient", "left_cauchy_green_ob", "yield_function", "equivalent_plastic_strain"};
  }
  const HerschelBulkleyParameters& parameters() const { return parameters_; }
  /// Ŝ(A) of §4.6.2 for particle p.
  FlowStrainMap flow_strain_map(const particles::ParticleSet& particles, std::size_t p, double dt) const;

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  /// Stores F̂ and Ŝ(A), then rescales b_HB to unit determinant (b^E does not depend on its scale);
  /// records the yield function and accumulates √(2/3) Δt × plastic rate.
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  HerschelBulkleyParameters parameters_;
  ViscosityConvention convention_;
  std::string model_;
};

}  // namespace viscompm::materials
