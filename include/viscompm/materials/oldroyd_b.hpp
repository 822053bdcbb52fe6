// The volume-preserving Oldroyd-B model of Chapter 5: Neo-Hookean elasticity (5.8) of
// b^E = (J / J_OB)^{2/3} b_OB (5.5, 5.13), b_OB updated by one of three schemes ("Strain update"):
//   paper: the upper-convected scheme (5.14), linear in A;
//   spd:   the update of §4.6.1, b_OB symmetric positive definite for every Δt (quadratic in A);
//   f_e:   the recast of §4.7.1, which stores f_e and b_OB = f_e f_e^T (quadratic in A);
// plus the Newtonian viscous potential (5.11) in one of two conventions (doc/numerics.md):
//   paper:    Φ^N = μ^N ε̂:ε̂ V^n        (μ^N acts as a viscosity μ^N / Δt)
//   physical: Φ^N = Δt η ε̂:ε̂ V^n       (σ^N = 2 η ε, independent of Δt)
// on ε̂ itself ("Viscous strain" full, the thesis) or on dev ε̂ only (deviatoric: no viscous
// resistance to a change of volume).
#pragma once

#include <Eigen/Core>

#include "viscompm/core/parameters.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/materials/shared_parameters.hpp"
#include "viscompm/materials/strain_maps.hpp"

namespace viscompm::materials {

enum class OldroydBUpdate { paper, spd, f_e };

struct OldroydBParameters : ElasticParameters, NewtonianParameters {
  double weissenberg = 1.0;           ///< Wi
  OldroydBUpdate strain_update = OldroydBUpdate::paper;

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
  ViscousStrain viscous_strain = ViscousStrain::full;  ///< Φ^N of ε̂ (full) or of dev ε̂ (deviatoric)
};

/// The part of ε̂ the viscous potential acts on: ε̂ (full) or dev ε̂ = ε̂ − (tr ε̂/3) I.
Mat3 viscous_strain(const Coefficients& c, const Mat3& eps);

/// ∂Ψ/∂y as three matrices.
struct EnergyGradient {
  Mat3 F, S, eps;
};
/// The non-zero blocks of ∂²Ψ/∂y² (the ε block is 2 c_N J^n times the identity, full, or times
/// the deviatoric projector I − vec(I) vec(I)ᵀ/3, deviatoric).
struct EnergyHessian {
  Mat9 FF, FS, SS, eps_eps;
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

/// b^E = (J / J_OB)^{2/3} b_OB of (5.5).
Mat3 elastic_left_cauchy_green(const Mat3& F, const Mat3& b_ob);

/// Φ_p = V Ψ(F̂, Ŝ, ε̂) with F̂ = (I + A) F^n (5.12), Ŝ = map(A) and ε̂ = sym(A)/Δt, and its
/// derivatives in A (order 0, 1, 2). Shared by the Oldroyd-B updates and the Herschel–Bulkley-like
/// fluid of §4.6.2, which uses "the analogous strain density from Chapter 5". False if infeasible.
bool evaluate_potential(const Coefficients& c, const Mat3& F_n, const FlowStrainMap& map, const Mat3& A,
                        double dt, double volume, int order, PotentialDerivatives& out);

}  // namespace oldroyd_b

class OldroydB : public Material {
 public:
  OldroydB(std::string name, const OldroydBParameters& parameters);

  std::string model() const override { return "oldroyd_b"; }
  double density() const override { return parameters_.density; }
  double wave_speed() const override;
  std::vector<std::string> state_fields() const override;
  const OldroydBParameters& parameters() const { return parameters_; }
  OldroydBUpdate update() const { return update_; }
  /// c_N of the viscous potential for a step of size dt.
  double viscous_coefficient(double dt) const;
  /// Ŝ(A) of this model's update for particle p (b_OB of the step, or f_e for the f_e update).
  FlowStrainMap flow_strain_map(const particles::ParticleSet& particles, std::size_t p, double dt) const;

  bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                const StepContext& step, int order, PotentialDerivatives& out) const override;
  void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                    const StepContext& step) const override;
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const override;

 private:
  OldroydBParameters parameters_;
  ViscosityConvention convention_;
  OldroydBUpdate update_;
};

}  // namespace viscompm::materials
