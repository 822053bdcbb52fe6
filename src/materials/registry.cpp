#include "viscompm/materials/registry.hpp"

#include <type_traits>

#include "viscompm/materials/herschel_bulkley.hpp"
#include "viscompm/materials/neo_hookean.hpp"
#include "viscompm/materials/oldroyd_b.hpp"
#include "viscompm/materials/svd_plasticity.hpp"
#include "viscompm/materials/von_mises.hpp"

namespace viscompm::materials {

namespace {
// Every model has μ and λ: their bulk modulus λ + 2μ/3 must be positive.
std::optional<ParameterProblem> check_elastic(const ParameterValues& values) {
  return check_bulk_modulus(values.real("Shear modulus"), values.real("Lame lambda"));
}

template <class Model, class Parameters>
ModelEntry entry(std::string model, std::string summary,
                 const ParameterTable<Parameters>& (*table)() = &Parameters::table) {
  ModelEntry e;
  e.model = std::move(model);
  e.summary = std::move(summary);
  e.parameters = table().specs();
  e.create = [table, model = e.model](const std::string& name, const ParameterValues& values) -> std::unique_ptr<Material> {
    // A model class serving several registry names (herschel_bulkley, bingham) is told which.
    if constexpr (std::is_constructible_v<Model, std::string, Parameters, std::string>)
      return std::make_unique<Model>(name, table().parse(values), model);
    else
      return std::make_unique<Model>(name, table().parse(values));
  };
  e.check = check_elastic;
  return e;
}
}  // namespace

const std::vector<ModelEntry>& model_registry() {
  static const std::vector<ModelEntry> registry = {
      entry<OldroydB, OldroydBParameters>(
          "oldroyd_b",
          "volume-preserving Oldroyd-B viscoelasticity (Chapter 5) with the b_OB update (5.14), the "
          "positive-definite one of §4.6.1 or the f_e recast of §4.7"),
      entry<HerschelBulkley, HerschelBulkleyParameters>(
          "herschel_bulkley",
          "Herschel-Bulkley-like viscoplastic fluid with the positive-definite update of §4.6.2 and the volume "
          "correction of Chapter 5 (§4.2.5: h < 1 shear thinning, h > 1 thickening)"),
      entry<HerschelBulkley, HerschelBulkleyParameters>(
          "bingham", "Bingham viscoplastic fluid: herschel_bulkley with h = 1 (§4.2.4)",
          &HerschelBulkleyParameters::bingham_table),
      entry<NeoHookean, NeoHookeanParameters>("neo_hookean",
                                              "compressible Neo-Hookean elasticity (§2.5.4, (5.8)), no plasticity"),
      entry<SvdPlasticity, SvdPlasticityParameters>(
          "svd_plasticity",
          "elastoplasticity by clamping the singular values of F_E (§4.4) with hardening (ζ > 0, §4.5.1) or "
          "softening (ζ < 0, §4.5.2)"),
      entry<VonMises, VonMisesParameters>(
          "von_mises", "isochoric von Mises elastoplasticity with a radial return mapping (§4.2.6, §4.3)"),
  };
  return registry;
}

const ModelEntry* find_model(const std::string& model) {
  for (const auto& e : model_registry())
    if (e.model == model) return &e;
  return nullptr;
}

std::vector<std::string> model_names() {
  std::vector<std::string> names;
  for (const auto& e : model_registry()) names.push_back(e.model);
  return names;
}

}  // namespace viscompm::materials
