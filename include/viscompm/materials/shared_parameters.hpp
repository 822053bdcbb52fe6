// Parameters several models share, declared once here: the density and Lamé parameters of every
// model, with the check that they describe a stable material (μ ≥ 0 and a positive bulk modulus
// λ + 2μ/3), and the Newtonian viscosity of (5.11) with its convention and the part of ε̂ it acts
// on (doc/numerics.md).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include "viscompm/core/error.hpp"
#include "viscompm/core/parameters.hpp"

namespace viscompm::materials {

struct ElasticParameters {
  double density = 1.0;
  double shear_modulus = 1.0;  ///< μ
  double lame_lambda = 1.0;    ///< λ
};

/// Declares Density, Shear modulus and Lame lambda on the table of a struct derived from
/// ElasticParameters; `energy` names the energy they enter, e.g. "(5.8)".
template <class P>
void add_elastic_parameters(ParameterTable<P>& table, const std::string& energy) {
  // Below 1e-3 kg/m^3 is no material (hydrogen at room conditions has 0.08, the lightest aerogels
  // about 0.2): a continuum of particles of such mass is a typo (issue 24).
  table.real(static_cast<double P::*>(&ElasticParameters::density), "Density", 1.0, Range::at_least(1e-3),
             "mass density ρ [kg/m^3], at least 1e-3 (below any material's)")
      .real(static_cast<double P::*>(&ElasticParameters::shear_modulus), "Shear modulus", 1.0,
            Range::non_negative(), "Neo-Hookean μ of " + energy + " [Pa]")
      .real(static_cast<double P::*>(&ElasticParameters::lame_lambda), "Lame lambda", 1.0, Range::any(),
            "Neo-Hookean λ of " + energy + "; λ + 2μ/3 (the bulk modulus) must be positive [Pa]");
}

enum class ViscosityConvention { paper, physical };
/// c_N of the viscous potential Φ^N = c_N ε̂:ε̂ V^n for a step of size dt: μ^N as (5.11) (paper)
/// or Δt η (physical, σ^N = 2ηε).
inline double viscous_coefficient(ViscosityConvention convention, double viscosity, double dt) {
  return convention == ViscosityConvention::paper ? viscosity : dt * viscosity;
}

/// The strain rate the Newtonian potential (5.11) acts on: ε̂ itself (full, the thesis), which also
/// resists a change of volume with a bulk viscosity 2c_N/3, or its deviatoric part dev ε̂ =
/// ε̂ − (tr ε̂/3) I, which leaves the volume to the elastic response alone.
enum class ViscousStrain { full, deviatoric };

struct NewtonianParameters {
  double newtonian_viscosity = 0.0;              ///< μ^N (paper) or η (physical)
  ViscosityConvention viscosity_convention = ViscosityConvention::physical;
  ViscousStrain viscous_strain = ViscousStrain::full;
};

/// Declares Newtonian viscosity, Viscosity convention and Viscous strain on the table of a struct
/// derived from NewtonianParameters.
template <class P>
void add_newtonian_parameters(ParameterTable<P>& table) {
  table.real(static_cast<double P::*>(&NewtonianParameters::newtonian_viscosity), "Newtonian viscosity", 0.0,
             Range::non_negative(), "μ^N of (5.11) in the paper convention [Pa], η in the physical one [Pa s]")
      .choice(static_cast<ViscosityConvention P::*>(&NewtonianParameters::viscosity_convention),
              "Viscosity convention", ViscosityConvention::physical,
              {{"paper", ViscosityConvention::paper}, {"physical", ViscosityConvention::physical}},
              "paper: Φ^N = μ^N ε̂:ε̂ V^n exactly as (5.11); physical: σ^N = 2ηε")
      .choice(static_cast<ViscousStrain P::*>(&NewtonianParameters::viscous_strain), "Viscous strain",
              ViscousStrain::full, {{"full", ViscousStrain::full}, {"deviatoric", ViscousStrain::deviatoric}},
              "what (5.11) acts on: full, ε̂ as the thesis (the volume rate resisted too); deviatoric, dev ε̂ "
              "only (the volume left to the elastic response)");
}

/// A problem with one parameter found by a cross-parameter check.
struct ParameterProblem {
  std::string parameter;  ///< the parameter's name in its sublist, e.g. "Lame lambda"
  std::string reason;     ///< one line
};

/// The bulk modulus λ + 2μ/3 of the linearised energy must be positive (λ may be negative: an
/// auxetic foam), else a uniform compression would release energy.
inline std::optional<ParameterProblem> check_bulk_modulus(double shear_modulus, double lame_lambda) {
  const double bulk_modulus = lame_lambda + 2.0 * shear_modulus / 3.0;
  if (bulk_modulus > 0.0) return std::nullopt;
  std::ostringstream reason;
  reason << "the bulk modulus λ + 2μ/3 = " << bulk_modulus << " must be positive";
  return ParameterProblem{"Lame lambda", reason.str()};
}

/// √(max(λ + 2μ, 0)/ρ): the speed of the fastest elastic wave.
inline double elastic_wave_speed(double density, double mu, double lambda) {
  return std::sqrt(std::max(0.0, lambda + 2.0 * mu) / density);
}

}  // namespace viscompm::materials
