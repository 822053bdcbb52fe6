// Declarations of input parameters: every parameter is declared once, with its type, default,
// valid range and a one-line doc string, and bound to the member of the typed struct it fills.
// The scene layer turns these declarations into Teuchos validators; physics code sees only the
// typed structs.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "viscompm/core/types.hpp"

namespace viscompm {

using RealList = std::vector<double>;
using StringList = std::vector<std::string>;
using ParameterValue = std::variant<double, int, bool, std::string, Vec3, RealList, StringList>;

struct ParameterSpec {
  enum class Type { real, integer, boolean, string, vector3, real_list, string_list };

  std::string name;
  Type type = Type::real;
  ParameterValue default_value = 0.0;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_inclusive = true;
  bool max_inclusive = true;
  std::vector<std::string> choices;  ///< allowed values of a string parameter (empty: any)
  std::string doc;

  /// One-line description of the valid range, e.g. "(0, inf)" or "one of: apic, pic_flip".
  std::string range_text() const;
  /// Empty if `value` is valid, else a one-line reason.
  std::string check(const ParameterValue& value) const;
  static std::string type_name(Type type);
};

/// Interval bounds for real and integer parameters.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_inclusive = true;
  bool max_inclusive = true;
  static Range any() { return {}; }
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), false, true}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), true, true}; }
  static Range closed(double lo, double hi) { return {lo, hi, true, true}; }
  static Range open_closed(double lo, double hi) { return {lo, hi, false, true}; }
  static Range at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, true}; }
};

/// Values read from input, by parameter name.
class ParameterValues {
 public:
  void set(const std::string& name, ParameterValue value) { values_[name] = std::move(value); }
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  const ParameterValue& at(const std::string& name) const;
  double real(const std::string& name) const { return std::get<double>(at(name)); }
  int integer(const std::string& name) const { return std::get<int>(at(name)); }
  bool boolean(const std::string& name) const { return std::get<bool>(at(name)); }
  const std::string& string(const std::string& name) const { return std::get<std::string>(at(name)); }
  const Vec3& vector3(const std::string& name) const { return std::get<Vec3>(at(name)); }
  const RealList& real_list(const std::string& name) const { return std::get<RealList>(at(name)); }
  const StringList& string_list(const std::string& name) const { return std::get<StringList>(at(name)); }

 private:
  std::map<std::string, ParameterValue> values_;
};

/// The declarations of one typed struct's parameters, each bound to a member.
template <class Struct>
class ParameterTable {
 public:
  ParameterTable& real(double Struct::*member, std::string name, double default_value, Range range,
                       std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::real, default_value, range, {}, std::move(doc)));
  }
  ParameterTable& integer(int Struct::*member, std::string name, int default_value, Range range,
                          std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::integer, default_value, range, {}, std::move(doc)));
  }
  ParameterTable& boolean(bool Struct::*member, std::string name, bool default_value, std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::boolean, default_value, {}, {}, std::move(doc)));
  }
  /// A string; `choices` empty means any string.
  ParameterTable& string(std::string Struct::*member, std::string name, std::string default_value,
                         std::vector<std::string> choices, std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::string, std::move(default_value), {},
                             std::move(choices), std::move(doc)));
  }
  /// A string from a fixed list, parsed once into an enum: `choices` pairs each name with its value.
  template <class Enum>
  ParameterTable& choice(Enum Struct::*member, std::string name, Enum default_value,
                         std::vector<std::pair<std::string, Enum>> choices, std::string doc) {
    std::vector<std::string> names;
    std::string default_name;
    for (const auto& [n, e] : choices) {
      names.push_back(n);
      if (e == default_value) default_name = n;
    }
    specs_.push_back(make(std::move(name), ParameterSpec::Type::string, default_name, {}, std::move(names), std::move(doc)));
    setters_.push_back([member, choices](Struct& s, const ParameterValue& v) {
      for (const auto& [n, e] : choices)
        if (n == std::get<std::string>(v)) s.*member = e;
    });
    return *this;
  }
  ParameterTable& vector3(Vec3 Struct::*member, std::string name, Vec3 default_value, std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::vector3, default_value, {}, {}, std::move(doc)));
  }

  /// A list of numbers; each must lie in `range`.
  ParameterTable& real_list(RealList Struct::*member, std::string name, RealList default_value, Range range,
                            std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::real_list, std::move(default_value), range, {},
                             std::move(doc)));
  }
  ParameterTable& string_list(StringList Struct::*member, std::string name, StringList default_value, std::string doc) {
    return bind(member, make(std::move(name), ParameterSpec::Type::string_list, std::move(default_value), {}, {},
                             std::move(doc)));
  }

  const std::vector<ParameterSpec>& specs() const { return specs_; }

  /// Fills a struct from validated values (missing values take their defaults).
  Struct parse(const ParameterValues& values) const {
    Struct s{};
    for (std::size_t k = 0; k < specs_.size(); ++k)
      setters_[k](s, values.has(specs_[k].name) ? values.at(specs_[k].name) : specs_[k].default_value);
    return s;
  }

 private:
  static ParameterSpec make(std::string name, ParameterSpec::Type type, ParameterValue default_value,
                            Range range, std::vector<std::string> choices, std::string doc) {
    ParameterSpec spec;
    spec.name = std::move(name);
    spec.type = type;
    spec.default_value = std::move(default_value);
    spec.min = range.min;
    spec.max = range.max;
    spec.min_inclusive = range.min_inclusive;
    spec.max_inclusive = range.max_inclusive;
    spec.choices = std::move(choices);
    spec.doc = std::move(doc);
    return spec;
  }
  template <class T>
  ParameterTable& bind(T Struct::*member, ParameterSpec spec) {
    specs_.push_back(std::move(spec));
    setters_.push_back([member](Struct& s, const ParameterValue& v) { s.*member = std::get<T>(v); });
    return *this;
  }

  std::vector<ParameterSpec> specs_;
  std::vector<std::function<void(Struct&, const ParameterValue&)>> setters_;
};

}  // namespace viscompm
