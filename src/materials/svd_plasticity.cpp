#include "viscompm/materials/svd_plasticity.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

// GCC 12 reports JacobiSVD<Matrix3d>'s singular values as maybe uninitialized at -O3 (a false
// positive inside Eigen: compute() fills them before any read).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace viscompm::materials {

const ParameterTable<SvdPlasticityParameters>& SvdPlasticityParameters::table() {
  static const ParameterTable<SvdPlasticityParameters> t = [] {
    ParameterTable<SvdPlasticityParameters> table;
    using P = SvdPlasticityParameters;
    add_elastic_parameters(table, "§2.5.4 / (5.8), at J_P = 1");
    table.real(&P::critical_compression, "Critical compression", 2.5e-2, Range{0.0, 1.0, false, false},
               "c of §4.4: singular values of F_E below 1 − c flow plastically [1]")
        .real(&P::critical_stretch, "Critical stretch", 7.5e-3, Range::positive(),
              "s of §4.4: singular values of F_E above 1 + s flow plastically [1]")
        .real(&P::hardening, "Hardening coefficient", 10.0, Range::any(),
              "ζ of §4.5: μ, λ scale by e^{ζ(1 − J_P)}; > 0 hardens (§4.5.1), < 0 softens (§4.5.2) under "
              "plastic compression [1]");
    return table;
  }();
  return t;
}

namespace svd_plasticity {

neo_hookean::Lame hardened_lame(const SvdPlasticityParameters& parameters, double plastic_jacobian) {
  const double factor = std::exp(parameters.hardening * (1.0 - plastic_jacobian));  // §4.5.1
  return {parameters.shear_modulus * factor, parameters.lame_lambda * factor};
}

}  // namespace svd_plasticity

SvdPlasticity::SvdPlasticity(std::string name, const SvdPlasticityParameters& parameters)
    : Material(std::move(name)), parameters_(parameters) {}

double SvdPlasticity::wave_speed() const {
  return elastic_wave_speed(parameters_.density, parameters_.shear_modulus, parameters_.lame_lambda);
}

neo_hookean::Lame SvdPlasticity::lame(const particles::ParticleSet& particles, std::size_t p) const {
  return svd_plasticity::hardened_lame(parameters_, particles.plastic_deformation_gradient[p].determinant());
}

bool SvdPlasticity::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                             const StepContext&, int order, PotentialDerivatives& out) const {
  return neo_hookean::evaluate_potential(lame(particles, p), particles.elastic_deformation_gradient[p], A,
                                         particles.volume0[p], order, out);
}

void SvdPlasticity::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                                 const StepContext&) const {
  Mat3& F = particles.deformation_gradient[p];
  Mat3& F_E = particles.elastic_deformation_gradient[p];
  F = (Mat3::Identity() + A) * F;                   // (5.12)
  // The elastic predictor of the energy, F̂_E = U Σ Vᵀ (§4.4).
  const Eigen::JacobiSVD<Mat3> svd((Mat3::Identity() + A) * F_E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3& sigma = svd.singularValues();
  const double c = parameters_.critical_compression, s = parameters_.critical_stretch;
  particles.yield_function[p] = std::max((1.0 - c) - sigma.minCoeff(), sigma.maxCoeff() - (1.0 + s));
  const Vec3 clamped = sigma.cwiseMax(1.0 - c).cwiseMin(1.0 + s);
  F_E = svd.matrixU() * clamped.asDiagonal() * svd.matrixV().transpose();  // F_E ← U Σ̂ Vᵀ
  particles.plastic_deformation_gradient[p] =                              // F_P ← V Σ̂⁻¹ Uᵀ F
      svd.matrixV() * clamped.cwiseInverse().asDiagonal() * svd.matrixU().transpose() * F;
}

Mat3 SvdPlasticity::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  const Mat3& F_E = particles.elastic_deformation_gradient[p];
  return F_E * F_E.transpose();
}

}  // namespace viscompm::materials
