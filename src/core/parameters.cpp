#include "viscompm/core/parameters.hpp"

#include <cmath>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm {

namespace {
std::string number_text(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (std::isnan(x)) return "nan";
  std::ostringstream s;
  s << x;
  return s.str();
}

// Empty if x is a finite number inside the range, else the reason.
std::string range_problem(const ParameterSpec& spec, double x) {
  if (!std::isfinite(x)) return "value " + number_text(x) + " is not a finite number";
  const bool ok = (spec.min_inclusive ? x >= spec.min : x > spec.min) && (spec.max_inclusive ? x <= spec.max : x < spec.max);
  return ok ? std::string() : "value " + number_text(x) + " is out of range " + spec.range_text();
}
}  // namespace

std::string ParameterSpec::type_name(Type type) {
  switch (type) {
    case Type::real: return "double";
    case Type::integer: return "int";
    case Type::boolean: return "bool";
    case Type::string: return "string";
    case Type::vector3: return "Array(double)";
    case Type::real_list: return "Array(double)";
    case Type::string_list: return "Array(string)";
  }
  return "?";
}

std::string ParameterSpec::range_text() const {
  if (type == Type::real || type == Type::integer || type == Type::real_list) {
    return std::string(type == Type::real_list ? "each in " : "") + std::string(min_inclusive ? "[" : "(") + number_text(min) + ", " + number_text(max) +
           (max_inclusive ? "]" : ")");
  }
  if (type == Type::string && !choices.empty()) {
    std::string text = "one of:";
    for (std::size_t k = 0; k < choices.size(); ++k) text += (k ? ", " : " ") + choices[k];
    return text;
  }
  if (type == Type::vector3) return "3 numbers";
  return "any";
}

std::string ParameterSpec::check(const ParameterValue& value) const {
  if (type == Type::real || type == Type::integer) {
    return range_problem(*this, type == Type::real ? std::get<double>(value) : std::get<int>(value));
  } else if (type == Type::string && !choices.empty()) {
    const auto& s = std::get<std::string>(value);
    for (const auto& c : choices)
      if (c == s) return {};
    return "value '" + s + "' is not " + range_text();
  } else if (type == Type::real_list) {
    const auto& list = std::get<RealList>(value);
    for (double x : list)
      if (const std::string problem = range_problem(*this, x); !problem.empty()) return problem;
  } else if (type == Type::vector3) {
    const auto& v = std::get<Vec3>(value);
    if (!v.allFinite()) return "value has a non-finite component (every component must be a finite number)";
  }
  return {};
}

const ParameterValue& ParameterValues::at(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw InputError("missing parameter '" + name + "'");
  return it->second;
}

}  // namespace viscompm
