#include "viscompm/materials/oldroyd_b.hpp"

#include <Eigen/LU>
#include <cmath>

#include "viscompm/core/error.hpp"

namespace viscompm::materials {

ViscosityConvention viscosity_convention_from_name(const std::string& name) {
  if (name == "paper") return ViscosityConvention::paper;
  if (name == "physical") return ViscosityConvention::physical;
  throw InputError("unknown viscosity convention '" + name + "' (expected paper or physical)");
}

const ParameterTable<OldroydBParameters>& OldroydBParameters::table() {
  static const ParameterTable<OldroydBParameters> t = [] {
    ParameterTable<OldroydBParameters> table;
    using P = OldroydBParameters;
    table.real(&P::density, "Density", 1.0, Range::positive(), "mass density ρ [kg/m^3]")
        .real(&P::shear_modulus, "Shear modulus", 1.0, Range::non_negative(),
              "Neo-Hookean μ of (5.8) [Pa]")
        .real(&P::lame_lambda, "Lame lambda", 1.0, Range::non_negative(),
              "Neo-Hookean λ of (5.8) [Pa]")
        .real(&P::newtonian_viscosity, "Newtonian viscosity", 0.0, Range::non_negative(),
              "μ^N of (5.11) in the paper convention [Pa], η in the physical one [Pa s]")
        .string(&P::viscosity_convention, "Viscosity convention", "physical", {"paper", "physical"},
                "paper: Φ^N = μ^N ε̂:ε̂ V^n exactly as (5.11); physical: σ^N = 2ηε")
        .real(&P::weissenberg, "Weissenberg number", 1.0, Range::positive(),
              "relaxation time Wi of b_OB toward I (§5.4.3) [s]");
    return table;
  }();
  return t;
}

namespace oldroyd_b {
namespace {

// a[(i,j)] = (M^{-T})_{ij}
Vec9 inverse_transpose_vec(const Mat3& inverse) { return vec(inverse.transpose()); }

// Q[(i,j),(m,n)] = M^{-1}_{jm} M^{-1}_{ni}: minus the derivative of M^{-T} with respect to M.
Mat9 inverse_derivative(const Mat3& inverse) {
  Mat9 q;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int m = 0; m < 3; ++m)
        for (int n = 0; n < 3; ++n)
          q(vec_index(i, j), vec_index(m, n)) = inverse(j, m) * inverse(n, i);
  return q;
}

// The scalar e = μ/2 J^{2/3} det(S)^{-1/3} tr(S): the trace term of ψ(b^E).
double trace_term(double mu, double J, const Mat3& S) {
  return 0.5 * mu * std::cbrt(J * J / S.determinant()) * S.trace();
}
}  // namespace

bool feasible(const Mat3& F, const Mat3& S) {
  return F.determinant() > 0.0 && S.determinant() > 0.0 && S.trace() > 0.0;
}

double energy_density(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps) {
  const double J = F.determinant();
  const double e = trace_term(c.mu, J, S);
  return e - 1.5 * c.mu - c.mu * std::log(J) + 0.5 * c.lambda * (J - 1.0) * (J - 1.0) +
         c.viscous * c.J_n * eps.squaredNorm();
}

EnergyGradient energy_gradient_blocks(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps) {
  const double J = F.determinant();
  const double e = trace_term(c.mu, J, S);
  EnergyGradient g;
  g.F = (2.0 / 3.0 * e - c.mu + c.lambda * (J - 1.0) * J) * F.inverse().transpose();
  g.S = e * (-S.inverse().transpose() / 3.0 + Mat3::Identity() / S.trace());
  g.eps = 2.0 * c.viscous * c.J_n * eps;
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
  const Mat9 Q_F = inverse_derivative(F_inv);
  const Mat9 Q_S = inverse_derivative(S_inv);
  const Vec9 dlog_e_dS = -s / 3.0 + iota / T;  // ∂ ln e / ∂S
  const Mat9 aa = a * a.transpose();

  EnergyHessian h;
  // ∂²/∂F²: trace term, −μ ln J, and λ/2 (J−1)², with dJ = J a and d²J = J (a aᵀ − Q_F).
  h.FF = (4.0 / 9.0 * e + c.lambda * J * J + c.lambda * (J - 1.0) * J) * aa +
         (c.mu - 2.0 / 3.0 * e - c.lambda * (J - 1.0) * J) * Q_F;
  // ∂²/∂F∂S and ∂²/∂S² of the trace term: e (∇ln e ∇ln eᵀ + ∇² ln e).
  h.FS = e * 2.0 / 3.0 * a * dlog_e_dS.transpose();
  h.SS = e * (dlog_e_dS * dlog_e_dS.transpose() + Q_S / 3.0 - iota * iota.transpose() / (T * T));
  // ∂²/∂ε² of the viscous term.
  h.eps_eps = 2.0 * c.viscous * c.J_n;
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
  m.block<9, 9>(18, 18) = h.eps_eps * Mat9::Identity();
  return m;
}

Mat3 predicted_b_ob(const Mat3& S, const Mat3& A, double dt, double weissenberg) {
  const Mat3 B = A * S;
  return S + dt / weissenberg * (Mat3::Identity() - S) + B + B.transpose();
}

Mat3 elastic_left_cauchy_green(const Mat3& F, const Mat3& b_ob) {
  const double J = F.determinant();
  return std::cbrt(J * J / b_ob.determinant()) * b_ob;
}

}  // namespace oldroyd_b

namespace {
// The chain rule from y = (F̂, Ŝ, ε̂) to A. With dF̂ = dA F^n, dŜ = dA S + S dAᵀ and
// dε̂ = (dA + dAᵀ)/(2Δt), left multiplication by the transposed Jacobian Lᵀ acts on each column
// of a 9×N matrix reshaped as a 3×3 matrix C: C Fⁿᵀ, (C + Cᵀ) S, (C + Cᵀ)/(2Δt).
enum class Strain { F, S, eps };

struct ChainRule {
  const Mat3& F_n;
  const Mat3& S_n;
  double dt;

  Mat3 pull_back(Strain y, const Mat3& C) const {
    switch (y) {
      case Strain::F: return C * F_n.transpose();
      case Strain::S: return (C + C.transpose()) * S_n;
      case Strain::eps: return (C + C.transpose()) / (2.0 * dt);
    }
    return C;
  }
  // Lᵀ_y X, column by column.
  Mat9 left(Strain y, const Mat9& X) const {
    Mat9 out;
    for (int k = 0; k < 9; ++k) out.col(k) = vec(pull_back(y, unvec(X.col(k))));
    return out;
  }
  // Lᵀ_a X L_b.
  Mat9 sandwich(Strain a, const Mat9& X, Strain b) const {
    return left(a, left(b, X.transpose()).transpose());
  }
};
}  // namespace

OldroydB::OldroydB(std::string name, const OldroydBParameters& parameters)
    : Material(std::move(name)),
      parameters_(parameters),
      convention_(viscosity_convention_from_name(parameters.viscosity_convention)) {}

double OldroydB::wave_speed() const {
  return std::sqrt((parameters_.lame_lambda + 2.0 * parameters_.shear_modulus) / parameters_.density);
}

double OldroydB::viscous_coefficient(double dt) const {
  return convention_ == ViscosityConvention::paper ? parameters_.newtonian_viscosity
                                                   : dt * parameters_.newtonian_viscosity;
}

bool OldroydB::evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                        const StepContext& step, int order, PotentialDerivatives& out) const {
  const Mat3& F_n = particles.deformation_gradient[p];
  const Mat3& S_n = particles.left_cauchy_green_ob[p];
  const double volume = particles.volume0[p];
  // Cached quantities: the predicted strains of (5.12), (5.14) and ε̂.
  const Mat3 F_hat = (Mat3::Identity() + A) * F_n;
  const Mat3 S_hat = oldroyd_b::predicted_b_ob(S_n, A, step.dt, parameters_.weissenberg);
  const Mat3 eps_hat = 0.5 * (A + A.transpose()) / step.dt;
  if (!oldroyd_b::feasible(F_hat, S_hat)) return false;
  const oldroyd_b::Coefficients c{parameters_.shear_modulus, parameters_.lame_lambda,
                                  viscous_coefficient(step.dt), F_n.determinant()};
  out.energy = volume * oldroyd_b::energy_density(c, F_hat, S_hat, eps_hat);
  if (order < 1) return true;

  // ∂Φ/∂A = V Lᵀ ∂Ψ/∂y.
  const ChainRule chain{F_n, S_n, step.dt};
  const oldroyd_b::EnergyGradient g = oldroyd_b::energy_gradient_blocks(c, F_hat, S_hat, eps_hat);
  out.gradient = volume * (chain.pull_back(Strain::F, g.F) + chain.pull_back(Strain::S, g.S) +
                           chain.pull_back(Strain::eps, g.eps));
  if (order < 2) return true;

  // F̂, Ŝ and ε̂ are affine in A, so ∂²Φ/∂A² = V Lᵀ (∂²Ψ/∂y²) L.
  const oldroyd_b::EnergyHessian h = oldroyd_b::energy_hessian_blocks(c, F_hat, S_hat);
  const Mat9 cross = chain.sandwich(Strain::F, h.FS, Strain::S);
  out.hessian = volume * (chain.sandwich(Strain::F, h.FF, Strain::F) + cross + cross.transpose() +
                          chain.sandwich(Strain::S, h.SS, Strain::S) +
                          h.eps_eps * chain.sandwich(Strain::eps, Mat9::Identity(), Strain::eps));
  return true;
}

void OldroydB::update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                            const StepContext& step) const {
  Mat3& F = particles.deformation_gradient[p];
  Mat3& S = particles.left_cauchy_green_ob[p];
  S = oldroyd_b::predicted_b_ob(S, A, step.dt, parameters_.weissenberg);  // (5.14)
  F = (Mat3::Identity() + A) * F;                                         // (5.12)
}

Mat3 OldroydB::left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const {
  return oldroyd_b::elastic_left_cauchy_green(particles.deformation_gradient[p],
                                              particles.left_cauchy_green_ob[p]);
}

}  // namespace viscompm::materials
