#include "viscompm/materials/neo_hookean.hpp"

#include <Eigen/LU>
#include <cmath>

#include "viscompm/materials/strain_maps.hpp"

namespace viscompm::materials {

namespace neo_hookean {

double energy_density(const Lame& lame, const Mat3& F) {
  const double J = F.determinant();
  return 0.5 * lame.mu * (F.squaredNorm() - 3.0) - lame.mu * std::log(J) + 0.5 * lame.lambda * (J - 1.0) * (J - 1.0);
}

Mat3 first_piola(const Lame& lame, const Mat3& F) {
  const double J = F.determinant();
  return lame.mu * F + (lame.lambda * J * (J - 1.0) - lame.mu) * F.inverse().transpose();
}

Mat9 energy_hessian(const Lame& lame, const Mat3& F) {
  const double J = F.determinant();
  const Mat3 F_inv = F.inverse();
  const Vec9 a = vec(F_inv.transpose());
  // d(J F^{-T}) = J (a aᵀ − Q) dF and d(F^{-T}) = −Q dF, with dJ = J a:dF.
  return lame.mu * Mat9::Identity() + lame.lambda * (2.0 * J - 1.0) * J * a * a.transpose() +
         (lame.mu - lame.lambda * J * (J - 1.0)) * inverse_transpose_derivative(F_inv);
}

Mat3 kirchhoff_stress(const Lame& lame, const Mat3& F) {
  const double J = F.determinant();
  return lame.mu * (F * F.transpose() - Mat3::Identity()) + lame.lambda * J * (J - 1.0) * Mat3::Identity();
}

bool evaluate_potential(const Lame& lame, const Mat3& G, const Mat3& A, double volume, int order,
                        PotentialDerivatives& out) {
  const Mat3 F_hat = (Mat3::Identity() + A) * G;  // (5.12)
  if (!(F_hat.determinant() > 0.0)) return false;
  out.energy = volume * energy_density(lame, F_hat);
  if (order < 1) return true;
  // dF̂ = dA G: ∂Φ/∂A = V P Gᵀ and ∂²Φ/∂A² = V Lᵀ (∂²ψ/∂F²) L, F̂ affine in A.
  using Strain = StrainChainRule::Strain;
  const StrainChainRule chain{G, Mat3::Zero(), 1.0};
  out.gradient = volume * chain.pull_back(Strain::F, first_piola(lame, F_hat));
  if (order < 2) return true;
  out.hessian = volume * chain.sandwich(Strain::F, energy_hessian(lame, F_hat), Strain::F);
  return true;
}

}  // namespace neo_hookean

const ParameterTable<NeoHookeanParameters>& NeoHookeanParameters::table() {
  static const ParameterTable<NeoHookeanParameters> t = [] {
    ParameterTable<NeoHookeanParameters> table;
    add_elastic_parameters(table, "§2.5.4 / (5.8)");
    return table;
  }();
  return t;
}

NeoHookean::NeoHookean(std::string name, const NeoHookeanParameters& parameters)
    : Material(std::move(name)), parameters_(parameters) {}

double NeoHookean::wave_speed() const {
  return elastic_wave_speed(parameters_.density, parameters_.shear_modulus, parameters_.lame_lambda);
}

bool NeoHookean::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A, const StepContext&,
                          int order, PotentialDerivatives& out) const {
  return neo_hookean::evaluate_potential({parameters_.shear_modulus, parameters_.lame_lambda},
                                         particles.deformation_gradient[p], A, particles.volume0[p], order, out);
}

void NeoHookean::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                              const StepContext&) const {
  Mat3& F = particles.deformation_gradient[p];
  F = (Mat3::Identity() + A) * F;  // (5.12)
}

Mat3 NeoHookean::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  const Mat3& F = particles.deformation_gradient[p];
  return F * F.transpose();
}

}  // namespace viscompm::materials
