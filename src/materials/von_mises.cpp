#include "viscompm/materials/von_mises.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

namespace viscompm::materials {

const ParameterTable<VonMisesParameters>& VonMisesParameters::table() {
  static const ParameterTable<VonMisesParameters> t = [] {
    ParameterTable<VonMisesParameters> table;
    using P = VonMisesParameters;
    add_elastic_parameters(table, "(5.8)");
    table.real(&P::yield_stress, "Yield stress", 1.0, Range::positive(),
               "Y of §4.2.6: the material flows when (3/2 τ':τ')^{1/2} reaches Y + K ε (Kirchhoff stress) [Pa]")
        .real(&P::hardening_modulus, "Hardening modulus", 0.0, Range::non_negative(),
              "K of the linear isotropic hardening Y(ε) = Y + K ε, ε the equivalent plastic strain [Pa]");
    return table;
  }();
  return t;
}

namespace von_mises {
namespace {
Mat3 deviator(const Mat3& m) { return m - m.trace() / 3.0 * Mat3::Identity(); }

// m > −min d with Π (d_i + m) = target (d sorted or not): Σ ln(d_i + m) is increasing and concave
// in m, so Newton from a point left of the root converges monotonically; bisection guards it.
double spherical_part(const Vec3& d, double target_determinant, double start) {
  const double log_target = std::log(target_determinant);
  double lo = -d.minCoeff(), hi = std::max(start, lo + 1.0);
  auto g = [&](double m) { return (d.array() + m).log().sum() - log_target; };
  while (g(hi) < 0.0) hi = lo + 2.0 * (hi - lo);
  double m = start > lo && start < hi ? start : 0.5 * (lo + hi);
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double value = g(m);
    if (value < 0.0) lo = m; else hi = m;
    const double next = m - value / (d.array() + m).inverse().sum();
    const double previous = m;
    m = next > lo && next < hi ? next : 0.5 * (lo + hi);
    if (std::abs(m - previous) <= 1e-15 * std::abs(m)) break;
  }
  return m;
}
}  // namespace

double yield_function(const VonMisesParameters& parameters, const Mat3& b_elastic, double plastic_strain) {
  const Mat3 tau_dev = parameters.shear_modulus * deviator(b_elastic);  // dev of J·(5.9)
  return std::sqrt(1.5) * tau_dev.norm() - (parameters.yield_stress + parameters.hardening_modulus * plastic_strain);
}

ReturnMapping return_mapping(const VonMisesParameters& parameters, const Mat3& trial_F_E, double plastic_strain) {
  ReturnMapping r;
  r.elastic_deformation_gradient = trial_F_E;
  const Mat3 b_trial = trial_F_E * trial_F_E.transpose();
  r.trial_yield_function = yield_function(parameters, b_trial, plastic_strain);
  if (!(r.trial_yield_function > 0.0)) return r;

  // Radial return (Simo & Hughes, Box 9.1) with μ̄ = μ tr(b_tr)/3 and linear hardening.
  const double mu = parameters.shear_modulus, K = parameters.hardening_modulus;
  const double tau_dev_norm = mu * deviator(b_trial).norm();
  const double mu_bar = mu * b_trial.trace() / 3.0;
  const double delta_gamma = std::sqrt(2.0 / 3.0) * r.trial_yield_function / (2.0 * mu_bar + 2.0 * K / 3.0);
  r.plastic_strain_increment = std::sqrt(2.0 / 3.0) * delta_gamma;
  const double scale = 1.0 - 2.0 * mu_bar * delta_gamma / tau_dev_norm;  // τ' = scale τ'_tr

  // b^E = scale dev(b_tr) + m I, coaxial with b_tr, with det b^E = det b_tr (§4.3: J_P = 1).
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(b_trial);
  const Vec3& beta = eig.eigenvalues();
  const Vec3 d = scale * (beta.array() - beta.sum() / 3.0).matrix();
  const double m = spherical_part(d, beta.prod(), beta.sum() / 3.0);
  const Vec3 stretch_ratio = ((d.array() + m) / beta.array()).sqrt();
  // F_E = V R_tr with V = (b^E)^{1/2}: scale the predictor's left stretches along its principal axes.
  r.elastic_deformation_gradient = eig.eigenvectors() * stretch_ratio.asDiagonal() * eig.eigenvectors().transpose() * trial_F_E;
  return r;
}

}  // namespace von_mises

VonMises::VonMises(std::string name, const VonMisesParameters& parameters)
    : Material(std::move(name)), parameters_(parameters) {}

double VonMises::wave_speed() const {
  return elastic_wave_speed(parameters_.density, parameters_.shear_modulus, parameters_.lame_lambda);
}

bool VonMises::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A, const StepContext&,
                        int order, PotentialDerivatives& out) const {
  return neo_hookean::evaluate_potential({parameters_.shear_modulus, parameters_.lame_lambda},
                                         particles.elastic_deformation_gradient[p], A, particles.volume0[p], order, out);
}

void VonMises::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                            const StepContext&) const {
  Mat3& F = particles.deformation_gradient[p];
  Mat3& F_E = particles.elastic_deformation_gradient[p];
  F = (Mat3::Identity() + A) * F;  // (5.12)
  const von_mises::ReturnMapping r =
      von_mises::return_mapping(parameters_, (Mat3::Identity() + A) * F_E, particles.equivalent_plastic_strain[p]);
  F_E = r.elastic_deformation_gradient;
  particles.plastic_deformation_gradient[p] = F_E.inverse() * F;  // F = F_E F_P
  particles.yield_function[p] = r.trial_yield_function;
  particles.equivalent_plastic_strain[p] += r.plastic_strain_increment;
}

Mat3 VonMises::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  const Mat3& F_E = particles.elastic_deformation_gradient[p];
  return F_E * F_E.transpose();
}

}  // namespace viscompm::materials
