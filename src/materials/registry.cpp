#include "viscompm/materials/registry.hpp"

#include "viscompm/materials/oldroyd_b.hpp"

namespace viscompm::materials {

namespace {
template <class Model, class Parameters>
ModelEntry entry(std::string model, std::string summary) {
  ModelEntry e;
  e.model = std::move(model);
  e.summary = std::move(summary);
  e.parameters = Parameters::table().specs();
  e.create = [](const std::string& name, const ParameterValues& values) -> std::unique_ptr<Material> {
    return std::make_unique<Model>(name, Parameters::table().parse(values));
  };
  return e;
}
}  // namespace

const std::vector<ModelEntry>& model_registry() {
  static const std::vector<ModelEntry> registry = {
      entry<OldroydB, OldroydBParameters>(
          "oldroyd_b", "volume-preserving Oldroyd-B viscoelasticity with the update (5.14) (Chapter 5)"),
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
