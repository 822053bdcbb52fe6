#include "viscompm/materials/herschel_bulkley.hpp"

#include <Eigen/LU>
#include <cmath>

#include "viscompm/materials/oldroyd_b.hpp"

namespace viscompm::materials {

namespace {
template <class Table>
void add_flow_rule_parameters(Table& table) {
  using P = HerschelBulkleyParameters;
  add_elastic_parameters(table, "(5.8)");
  add_newtonian_parameters(table);
  table.real(&P::yield_stress, "Yield stress", 0.1, Range::non_negative(),
             "σ_Y of §4.6.2: the flow starts when ‖dev b̂‖ exceeds it, i.e. a deviatoric Kirchhoff stress of "
             "about μ σ_Y [1, in units of μ]")
      .real(&P::plastic_viscosity, "Plastic viscosity", 1.0, Range::positive(),
            "η of §4.6.2: plastic rate ((‖dev b̂‖ − σ_Y)/η)^{1/h} [s^h]");
}
}  // namespace

const ParameterTable<HerschelBulkleyParameters>& HerschelBulkleyParameters::table() {
  static const ParameterTable<HerschelBulkleyParameters> t = [] {
    ParameterTable<HerschelBulkleyParameters> table;
    add_flow_rule_parameters(table);
    table.real(&HerschelBulkleyParameters::flow_index, "Flow index", 1.0, Range::positive(),
               "h of §4.2.5: < 1 shear thinning, 1 Bingham, > 1 shear thickening [1]");
    return table;
  }();
  return t;
}

const ParameterTable<HerschelBulkleyParameters>& HerschelBulkleyParameters::bingham_table() {
  static const ParameterTable<HerschelBulkleyParameters> t = [] {
    ParameterTable<HerschelBulkleyParameters> table;
    add_flow_rule_parameters(table);
    return table;
  }();
  return t;
}

namespace herschel_bulkley {

Mat3 unimodular(const Mat3& b) { return b / std::cbrt(b.determinant()); }

namespace {
// ‖dev b̂‖ and tr b̂.
std::pair<double, double> deviatoric_norm_and_trace(const Mat3& b_hb) {
  const Mat3 b_hat = unimodular(b_hb);
  const double trace = b_hat.trace();
  return {(b_hat - trace / 3.0 * Mat3::Identity()).norm(), trace};
}
}  // namespace

double yield_function(const HerschelBulkleyParameters& parameters, const Mat3& b_hb) {
  return deviatoric_norm_and_trace(b_hb).first - parameters.yield_stress;
}

double plastic_rate(const HerschelBulkleyParameters& parameters, const Mat3& b_hb) {
  const double excess = yield_function(parameters, b_hb);
  if (!(excess > 0.0)) return 0.0;
  return std::pow(excess / parameters.plastic_viscosity, 1.0 / parameters.flow_index);  // §4.2.5
}

double plastic_coefficient(const HerschelBulkleyParameters& parameters, const Mat3& b_hb, double dt) {
  const auto [deviatoric_norm, trace] = deviatoric_norm_and_trace(b_hb);
  const double rate = plastic_rate(parameters, b_hb);
  if (rate == 0.0) return 0.0;
  return 2.0 * dt / 3.0 * trace * rate / deviatoric_norm;  // a of §4.6.2
}

}  // namespace herschel_bulkley

HerschelBulkley::HerschelBulkley(std::string name, const HerschelBulkleyParameters& parameters, std::string model)
    : Material(std::move(name)),
      parameters_(parameters),
      convention_(viscosity_convention_from_name(parameters.viscosity_convention)),
      model_(std::move(model)) {}

double HerschelBulkley::wave_speed() const {
  return elastic_wave_speed(parameters_.density, parameters_.shear_modulus, parameters_.lame_lambda);
}

FlowStrainMap HerschelBulkley::flow_strain_map(const particles::ParticleSet& particles, std::size_t p,
                                               double dt) const {
  const Mat3& b_hb = particles.left_cauchy_green_ob[p];
  return flow_strain_map_herschel_bulkley(b_hb, herschel_bulkley::plastic_coefficient(parameters_, b_hb, dt));
}

bool HerschelBulkley::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                               const StepContext& step, int order, PotentialDerivatives& out) const {
  const Mat3& F_n = particles.deformation_gradient[p];
  // "The analogous strain density from Chapter 5" (§4.6.2): (5.8) of (J/J_HB)^{2/3} b_HB, plus (5.11).
  const oldroyd_b::Coefficients c{parameters_.shear_modulus, parameters_.lame_lambda,
                                  viscous_coefficient(convention_, parameters_.newtonian_viscosity, step.dt),
                                  F_n.determinant()};
  return oldroyd_b::evaluate_potential(c, F_n, flow_strain_map(particles, p, step.dt), A, step.dt,
                                       particles.volume0[p], order, out);
}

void HerschelBulkley::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                                   const StepContext& step) const {
  Mat3& F = particles.deformation_gradient[p];
  Mat3& b_hb = particles.left_cauchy_green_ob[p];
  particles.yield_function[p] = herschel_bulkley::yield_function(parameters_, b_hb);
  particles.equivalent_plastic_strain[p] +=
      std::sqrt(2.0 / 3.0) * step.dt * herschel_bulkley::plastic_rate(parameters_, b_hb);
  b_hb = herschel_bulkley::unimodular(flow_strain_map(particles, p, step.dt).predict(A));  // §4.6.2
  F = (Mat3::Identity() + A) * F;                                                          // (5.12)
}

Mat3 HerschelBulkley::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  // b^E = (J/J_HB)^{2/3} b_HB (§4.6.2, as (5.5)).
  return oldroyd_b::elastic_left_cauchy_green(particles.deformation_gradient[p], particles.left_cauchy_green_ob[p]);
}

}  // namespace viscompm::materials
