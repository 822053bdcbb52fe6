// The volume-preserving Oldroyd-B model of Chapter 5: Neo-Hookean elasticity (5.8) of
// b^E = (J / J_OB)^{2/3} b_OB (5.5, 5.13), b_OB updated by the upper-convected scheme (5.14),
// plus the Newtonian viscous potential (5.11) in one of two conventions (DESIGN.md §3):
//   paper:    Φ^N = μ^N ε̂:ε̂ V^n        (μ^N acts as a viscosity μ^N / Δt)
//   physical: Φ^N = Δt η ε̂:ε̂ V^n       (σ^N = 2 η ε, independent of Δt)
#pragma once

#include <Eigen/Core>

#include "viscompm/core/parameters.hpp"
#include "viscompm/materials/material.hpp"

namespace viscompm::materials {

enum class ViscosityConvention { paper, physical };
ViscosityConvention viscosity_convention_from_name(const std::string& name);

struct OldroydBParameters {
  double density = 1.0;
  double shear_modulus = 1.0;         ///< μ
  double lame_lambda = 1.0;           ///< λ
  double newtonian_viscosity = 0.0;   ///< μ^N (paper) or η (physical)
  std::string viscosity_convention = "physical";
  double weissenberg = 1.0;           ///< Wi

  static const ParameterTable<OldroydBParameters>& table();
};

namespace oldroyd_b {

/// y = (vec F̂, vec Ŝ, vec ε̂): the variables Ψ depends on (Appendix A).
using Vec27 = Eigen::Matrix<double, 27, 1>;
using Mat27 = Eigen::Matrix<double, 27, 27>;

/// Constants of Ψ for one particle and step.
struct Coefficients {
  double mu = 0.0;
  double lambda = 0.0;
  double viscous = 0.0;   ///< c_N: μ^N (paper) or Δt η (physical)
  double J_n = 1.0;       ///< det(F^n): Φ^N integrates over the time-n volume V^n = J^n V^0
};

/// ∂Ψ/∂y as three matrices.
struct EnergyGradient {
  Mat3 F, S, eps;
};
/// The non-zero blocks of ∂²Ψ/∂y² (the ε block is a multiple of the identity).
struct EnergyHessian {
  Mat9 FF, FS, SS;
  double eps_eps = 0.0;
};

/// det F > 0, det S > 0 and tr S > 0 (§5.7).
bool feasible(const Mat3& F, const Mat3& S);
/// Ψ(F, S, ε) of Appendix A with the constant of (5.8), so that Ψ(I, I, 0) = 0.
double energy_density(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps);
/// ∂Ψ/∂y.
EnergyGradient energy_gradient_blocks(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps);
/// ∂²Ψ/∂y².
EnergyHessian energy_hessian_blocks(const Coefficients& c, const Mat3& F, const Mat3& S);
/// The same as 27-vectors and 27×27 matrices over y = (vec F, vec S, vec ε).
Vec27 energy_gradient(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps);
Mat27 energy_hessian(const Coefficients& c, const Mat3& F, const Mat3& S, const Mat3& eps);

/// Ŝ(A) of (5.14): S + A S + S A^T + (Δt/Wi)(I − S).
Mat3 predicted_b_ob(const Mat3& S, const Mat3& A, double dt, double weissenberg);
/// b^E = (J / J_OB)^{2/3} b_OB of (5.5).
Mat3 elastic_left_cauchy_green(const Mat3& F, const Mat3& b_ob);

}  // namespace oldroyd_b

class OldroydB : public Material {
 public:
  OldroydB(std::string name, const OldroydBParameters& parameters);

  std::string model() const override { return "oldroyd_b"; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  const OldroydBParameters& parameters() const { return parameters_; }
  /// c_N of the viscous potential for a step of size dt.
  double viscous_coefficient(double dt) const;

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  OldroydBParameters parameters_;
  ViscosityConvention convention_;
};

}  // namespace viscompm::materials
