#include "viscompm/materials/oldroyd_b.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "viscompm/core/error.hpp"

namespace viscompm::materials {

const ParameterTable<OldroydBParameters>& OldroydBParameters::table() {
  static const ParameterTable<OldroydBParameters> t = [] {
    ParameterTable<OldroydBParameters> table;
    using P = OldroydBParameters;
    add_elastic_parameters(table, "(5.8)");
    add_newtonian_parameters(table);
    table.real(&P::weissenberg, "Weissenberg number", 1.0, Range::positive(),
              "relaxation time Wi of b_OB toward I (§5.4.3) [s]")
        .choice(&P::strain_update, "Strain update", OldroydBUpdate::paper,
                {{"paper", OldroydBUpdate::paper}, {"spd", OldroydBUpdate::spd}, {"f_e", OldroydBUpdate::f_e}},
                "b_OB update: paper (5.14); spd, positive definite for all Δt (§4.6.1); f_e, stores f_e with "
                "b_OB = f_e f_e^T (§4.7.1)");
    return table;
  }();
  return t;
}

namespace oldroyd_b {
namespace {

// a[(i,j)] = (M^{-T})_{ij}
Vec9 inverse_transpose_vec(const Mat3& inverse) { return vec(inverse.transpose()); }

// The scalar e = μ/2 J^{2/3} det(S)^{-1/3} tr(S): the trace term of ψ(b^E).
double trace_term(double mu, double J, const Mat3& S) {
  return 0.5 * mu * std::cbrt(J * J / S.determinant()) * S.trace();
}
}  // namespace

Mat3 viscous_strain(const Coefficients& c, const Mat3& eps) {
  if (c.viscous_strain == ViscousStrain::full) return eps;
  return eps - eps.trace() / 3.0 * Mat3::Identity();
}

bool feasible(const Mat3& F, const Mat3& S) {
  return F.determinant() > 0.0 && S.determinant() > 0.0 && S.trace() > 0.0;
}

double energy_density(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps) {
  const double J = F.determinant();
  const double e = trace_term(c.mu, J, S);
  return e - 1.5 * c.mu - c.mu * std::log(J) + 0.5 * c.lambda * (J - 1.0) * (J - 1.0) +
         c.viscous * c.J_n * viscous_strain(c, eps).squaredNorm();
}

EnergyGradient energy_gradient_blocks(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps) {
  const double J = F.determinant();
  const double e = trace_term(c.mu, J, S);
  EnergyGradient g;
  g.F = (2.0 / 3.0 * e - c.mu + c.lambda * (J - 1.0) * J) * F.inverse().transpose();
  g.S = e * (-S.inverse().transpose() / 3.0 + Mat3::Identity() / S.trace());
  g.eps = 2.0 * c.viscous * c.J_n * viscous_strain(c, eps);  // dev is a projector: ∂(d:d)/∂ε = 2d
  return g;
}

EnergyHessian energy_hessian_blocks(const Coefficients& c, const Mat3& F, const Mat3& S) {
  const double J = F.determinant();
  const double T = S.trace();
  const double e = trace_term(c.mu, J, S);
  const Mat3 F_inv = F.inverse(), S_inv = S.inverse();
  const Vec9 a = inverse_transpose_vec(F_inv);
  const Vec9 s = inverse_transpose_vec(S_inv);
  const Vec9 iota = vec(Mat3::Identity());
  const Mat9 Q_F = inverse_transpose_derivative(F_inv);
  const Mat9 Q_S = inverse_transpose_derivative(S_inv);
  const Vec9 dlog_e_dS = -s / 3.0 + iota / T;  // ∂ ln e / ∂S
  const Mat9 aa = a * a.transpose();

  EnergyHessian h;
  // ∂²/∂F²: trace term, −μ ln J, and λ/2 (J−1)², with dJ = J a and d²J = J (a aᵀ − Q_F).
  h.FF = (4.0 / 9.0 * e + c.lambda * J * J + c.lambda * (J - 1.0) * J) * aa +
         (c.mu - 2.0 / 3.0 * e - c.lambda * (J - 1.0) * J) * Q_F;
  // ∂²/∂F∂S and ∂²/∂S² of the trace term: e (∇ln e ∇ln eᵀ + ∇² ln e).
  h.FS = e * 2.0 / 3.0 * a * dlog_e_dS.transpose();
  h.SS = e * (dlog_e_dS * dlog_e_dS.transpose() + Q_S / 3.0 - iota * iota.transpose() / (T * T));
  // ∂²/∂ε² of the viscous term: 2 c_N J^n times the projector ε ↦ ε (full) or ε ↦ dev ε.
  h.eps_eps = 2.0 * c.viscous * c.J_n * Mat9::Identity();
  if (c.viscous_strain == ViscousStrain::deviatoric)
    h.eps_eps -= 2.0 * c.viscous * c.J_n / 3.0 * iota * iota.transpose();
  return h;
}

Vec27 energy_gradient(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps) {
  const EnergyGradient g = energy_gradient_blocks(c, F, S, eps);
  Vec27 y;
  y << vec(g.F), vec(g.S), vec(g.eps);
  return y;
}

Mat27 energy_hessian(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3&) {
  const EnergyHessian h = energy_hessian_blocks(c, F, S);
  Mat27 m = Mat27::Zero();
  m.block<9, 9>(0, 0) = h.FF;
  m.block<9, 9>(0, 9) = h.FS;
  m.block<9, 9>(9, 0) = h.FS.transpose();
  m.block<9, 9>(9, 9) = h.SS;
  m.block<9, 9>(18, 18) = h.eps_eps;
  return m;
}

Mat3 elastic_left_cauchy_green(const Mat3& F, const Mat3& b_ob) {
  const double J = F.determinant();
  return std::cbrt(J * J / b_ob.determinant()) * b_ob;
}

bool evaluate_potential(const Coefficients& c, const Mat3& F_n, const FlowStrainMap& map, const Mat3& A,
                        double dt, double volume, int order, PotentialDerivatives& out) {
  // Cached quantities: the predicted strains of (5.12), of the b update, and ε̂.
  const Mat3 F_hat = (Mat3::Identity() + A) * F_n;
  const Mat3 S_hat = map.predict(A);
  const Mat3 eps_hat = 0.5 * (A + A.transpose()) / dt;
  if (!feasible(F_hat, S_hat)) return false;
  out.energy = volume * energy_density(c, F_hat, S_hat, eps_hat);
  if (order < 1) return true;

  // ∂Φ/∂A = V Lᵀ ∂Ψ/∂y.
  using Strain = StrainChainRule::Strain;
  const StrainChainRule chain{F_n, map.jacobian_factor(A), dt};
  const EnergyGradient g = energy_gradient_blocks(c, F_hat, S_hat, eps_hat);
  out.gradient = volume * (chain.pull_back(Strain::F, g.F) + chain.pull_back(Strain::S, g.S) +
                           chain.pull_back(Strain::eps, g.eps));
  if (order < 2) return true;

  // ∂²Φ/∂A² = V (Lᵀ (∂²Ψ/∂y²) L + ∂Ψ/∂S : ∂²Ŝ/∂A²); the last term only for a quadratic Ŝ(A).
  const EnergyHessian h = energy_hessian_blocks(c, F_hat, S_hat);
  const Mat9 cross = chain.sandwich(Strain::F, h.FS, Strain::S);
  out.hessian = volume * (chain.sandwich(Strain::F, h.FF, Strain::F) + cross + cross.transpose() +
                          chain.sandwich(Strain::S, h.SS, Strain::S) +
                          chain.sandwich(Strain::eps, h.eps_eps, Strain::eps));
  if (map.quadratic) out.hessian += volume * kronecker(map.K2, g.S + g.S.transpose());
  return true;
}

}  // namespace oldroyd_b

OldroydB::OldroydB(std::string name, const OldroydBParameters& parameters)
    : Material(std::move(name)),
      parameters_(parameters),
      convention_(parameters.viscosity_convention),
      update_(parameters.strain_update) {}

double OldroydB::wave_speed() const {
  return elastic_wave_speed(parameters_.density, parameters_.shear_modulus, parameters_.lame_lambda);
}

std::vector<std::string> OldroydB::state_fields() const {
  if (update_ == OldroydBUpdate::f_e)
    return {"deformation_gradient", "elastic_deformation_gradient", "left_cauchy_green_ob"};
  return {"deformation_gradient", "left_cauchy_green_ob"};
}

double OldroydB::viscous_coefficient(double dt) const {
  return materials::viscous_coefficient(convention_, parameters_.newtonian_viscosity, dt);
}

FlowStrainMap OldroydB::flow_strain_map(const particles::ParticleSet& particles, std::size_t p, double dt) const {
  const double wi = parameters_.weissenberg;
  switch (update_) {
    case OldroydBUpdate::paper: return flow_strain_map_paper(particles.left_cauchy_green_ob[p], dt, wi);
    case OldroydBUpdate::spd: return flow_strain_map_spd(particles.left_cauchy_green_ob[p], dt, wi);
    case OldroydBUpdate::f_e: return flow_strain_map_fe(particles.elastic_deformation_gradient[p], dt, wi);
  }
  return {};
}

bool OldroydB::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                        const StepContext& step, int order, PotentialDerivatives& out) const {
  const Mat3& F_n = particles.deformation_gradient[p];
  if (update_ == OldroydBUpdate::f_e) {
    // f̂ = (I + A) f + (Δt/2Wi)(f^{-T} − f) must stay orientation preserving (§4.7.1).
    const Mat3& f = particles.elastic_deformation_gradient[p];
    const Mat3 f_hat = predicted_fe_offset(f, step.dt, parameters_.weissenberg) + A * f;
    if (!(f_hat.determinant() > 0.0)) return false;
  }
  const oldroyd_b::Coefficients c{parameters_.shear_modulus, parameters_.lame_lambda,
                                  viscous_coefficient(step.dt), F_n.determinant(), parameters_.viscous_strain};
  return oldroyd_b::evaluate_potential(c, F_n, flow_strain_map(particles, p, step.dt), A, step.dt,
                                       particles.volume0[p], order, out);
}

void OldroydB::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                            const StepContext& step) const {
  Mat3& F = particles.deformation_gradient[p];
  Mat3& S = particles.left_cauchy_green_ob[p];
  if (update_ == OldroydBUpdate::f_e) {
    // §4.7.1: f_e^{n+1} = f_e + A f_e + (Δt/2Wi)(f_e^{-T} − f_e); b_OB = f_e f_eᵀ.
    Mat3& f = particles.elastic_deformation_gradient[p];
    f = predicted_fe_offset(f, step.dt, parameters_.weissenberg) + A * f;
    S = f * f.transpose();
  } else {
    S = flow_strain_map(particles, p, step.dt).predict(A);  // (5.14) or §4.6.1
  }
  F = (Mat3::Identity() + A) * F;  // (5.12)
}

Mat3 OldroydB::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  return oldroyd_b::elastic_left_cauchy_green(particles.deformation_gradient[p],
                                              particles.left_cauchy_green_ob[p]);
}

}  // namespace viscompm::materials
