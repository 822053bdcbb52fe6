// Constitutive models by name: the one place that lists them. A scene's material sublist names
// its model ("Model" = "oldroyd_b"); the registry gives that model's parameter declarations
// (for validation on read), its cross-parameter checks, and builds the material from validated
// values. doc/materials.md documents each entry.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscompm/core/parameters.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/materials/shared_parameters.hpp"

namespace viscompm::materials {

struct ModelEntry {
  std::string model;
  std::string summary;  ///< one line: what it is and which thesis section
  std::vector<ParameterSpec> parameters;
  std::function<std::unique_ptr<Material>(const std::string& name, const ParameterValues&)> create;
  /// Cross-parameter checks of range-validated values (e.g. a positive bulk modulus).
  std::function<std::optional<ParameterProblem>(const ParameterValues&)> check;
};

/// All models, in documentation order.
const std::vector<ModelEntry>& model_registry();
/// The entry for `model`, or nullptr.
const ModelEntry* find_model(const std::string& model);
/// Names of all models, for error messages and --help.
std::vector<std::string> model_names();

}  // namespace viscompm::materials
