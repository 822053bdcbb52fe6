// Every model of the registry in every variant (strain updates, viscosity conventions, viscous
// strains, flow indices, hardening and softening): the one list the derivative tests and
// bench_materials share.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "viscompm/materials/registry.hpp"

namespace viscompm::testkit {

struct ModelVariant {
  std::string label;
  std::string model;
  std::vector<std::pair<std::string, ParameterValue>> values;  ///< the rest take their defaults
};

/// The variants with μ = 3.6, λ = 14 and every stress-like parameter (moduli, yield stresses,
/// viscosities) multiplied by `stress_scale`; ρ = 2.
inline std::vector<ModelVariant> model_variants(double stress_scale = 1.0) {
  const double s = stress_scale;
  const std::vector<std::pair<std::string, ParameterValue>> elastic = {
      {"Density", 2.0}, {"Shear modulus", 3.6 * s}, {"Lame lambda", 14.0 * s}};
  auto with = [&](std::vector<std::pair<std::string, ParameterValue>> extra) {
    auto v = elastic;
    v.insert(v.end(), extra.begin(), extra.end());
    return v;
  };
  std::vector<ModelVariant> out;
  for (std::string update : {"paper", "spd", "f_e"})
    for (std::string convention : {"paper", "physical"})
      out.push_back({"oldroyd_b_" + update + "_" + convention, "oldroyd_b",
                     with({{"Strain update", update}, {"Viscosity convention", convention},
                           {"Newtonian viscosity", 0.3 * s}, {"Weissenberg number", 0.8}})});
  // (5.11) on dev ε̂ only ("Viscous strain"), for each update in the paper convention.
  for (std::string update : {"paper", "spd", "f_e"})
    out.push_back({"oldroyd_b_" + update + "_paper_deviatoric", "oldroyd_b",
                   with({{"Strain update", update}, {"Viscosity convention", "paper"}, {"Viscous strain", "deviatoric"},
                         {"Newtonian viscosity", 0.3 * s}, {"Weissenberg number", 0.8}})});
  for (double h : {0.5, 1.0, 2.0})
    out.push_back({"herschel_bulkley_h" + std::to_string(h), "herschel_bulkley",
                   with({{"Yield stress", 0.3 * s}, {"Plastic viscosity", 0.7 * s}, {"Flow index", h},
                         {"Newtonian viscosity", 0.2 * s}})});
  out.push_back({"herschel_bulkley_h1_deviatoric", "herschel_bulkley",
                 with({{"Yield stress", 0.3 * s}, {"Plastic viscosity", 0.7 * s}, {"Viscous strain", "deviatoric"},
                       {"Newtonian viscosity", 0.2 * s}})});
  out.push_back({"bingham", "bingham", with({{"Yield stress", 0.2 * s}, {"Plastic viscosity", 0.5 * s}})});
  out.push_back({"neo_hookean", "neo_hookean", elastic});
  out.push_back({"neo_hookean_negative_lambda", "neo_hookean", with({{"Lame lambda", -1.5 * s}})});
  for (double zeta : {10.0, -5.0})
    out.push_back({"svd_plasticity_zeta" + std::to_string(zeta), "svd_plasticity",
                   with({{"Critical compression", 0.1}, {"Critical stretch", 0.05}, {"Hardening coefficient", zeta}})});
  out.push_back({"von_mises", "von_mises", with({{"Yield stress", 0.5 * s}, {"Hardening modulus", 2.0 * s}})});
  return out;
}

/// A model's parameters with their declared defaults, except `values` (words such as
/// {"Strain update", "spd"} are parsed by the model's table, as a scene's are).
template <class Parameters>
Parameters parsed_parameters(const std::vector<std::pair<std::string, ParameterValue>>& values) {
  ParameterValues given;
  for (const auto& [name, value] : values) given.set(name, value);
  return Parameters::table().parse(given);
}

/// The material of a variant; throws std::invalid_argument if it names an undeclared parameter.
inline std::unique_ptr<materials::Material> build_material(const ModelVariant& v, const std::string& name) {
  const materials::ModelEntry* entry = materials::find_model(v.model);
  if (entry == nullptr) throw std::invalid_argument("no model " + v.model);
  ParameterValues values;
  for (const auto& spec : entry->parameters) values.set(spec.name, spec.default_value);
  for (const auto& [parameter, value] : v.values) {
    bool declared = false;
    for (const auto& spec : entry->parameters) declared |= spec.name == parameter;
    if (!declared) throw std::invalid_argument(v.model + " has no parameter " + parameter);
    values.set(parameter, value);
  }
  return entry->create(name, values);
}

}  // namespace viscompm::testkit
