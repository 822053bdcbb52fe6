#include "viscompm/params/parameter_io.hpp"

#include <Teuchos_Array.hpp>
#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <Teuchos_StringInputSource.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Teuchos_XMLParameterListReader.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::params {

namespace {

std::string joined(const std::string& path, const std::string& name) {
  return path.empty() ? name : path + "/" + name;
}

[[noreturn]] void fail(const std::string& file, const std::string& parameter, const std::string& reason) {
  throw InputError(file + ": parameter '" + parameter + "': " + reason);
}

std::string teuchos_type_name(const Teuchos::ParameterEntry& entry) {
  const auto& any = entry.getAny(false);
  if (any.type() == typeid(double)) return "double";
  if (any.type() == typeid(int)) return "int";
  if (any.type() == typeid(bool)) return "bool";
  if (any.type() == typeid(std::string)) return "string";
  if (any.type() == typeid(Teuchos::Array<double>)) return "Array(double)";
  if (any.type() == typeid(Teuchos::Array<int>)) return "Array(int)";
  if (any.type() == typeid(Teuchos::Array<std::string>)) return "Array(string)";
  return any.typeName();
}

// A Teuchos validator for one declared parameter: its one-line range check and docs.
class SpecValidator : public Teuchos::ParameterEntryValidator {
 public:
  explicit SpecValidator(ParameterSpec spec) : spec_(std::move(spec)) {}
  const std::string getXMLTypeName() const override { return "viscompmSpecValidator"; }
  void printDoc(const std::string& docString, std::ostream& out) const override {
    out << "# " << docString << "\n# valid: " << spec_.range_text() << "\n";
  }
  ValidStringsList validStringValues() const override {
    if (spec_.choices.empty()) return Teuchos::null;
    return Teuchos::rcp(new Teuchos::Array<std::string>(spec_.choices.begin(), spec_.choices.end()));
  }
  void validate(const Teuchos::ParameterEntry& entry, const std::string& name,
                const std::string& sublist) const override {
    const std::string reason = spec_.check(value_of(entry, name, sublist));
    if (!reason.empty())
      throw Teuchos::Exceptions::InvalidParameterValue(sublist + "/" + name + ": " + reason);
  }
  // The typed value of an entry; ints are accepted where doubles are declared.
  ParameterValue value_of(const Teuchos::ParameterEntry& entry, const std::string& name,
                          const std::string& sublist) const {
    const auto& any = entry.getAny(false);
    switch (spec_.type) {
      case ParameterSpec::Type::real:
        if (any.type() == typeid(double)) return Teuchos::any_cast<double>(any);
        if (any.type() == typeid(int)) return static_cast<double>(Teuchos::any_cast<int>(any));
        break;
      case ParameterSpec::Type::integer:
        if (any.type() == typeid(int)) return Teuchos::any_cast<int>(any);
        break;
      case ParameterSpec::Type::boolean:
        if (any.type() == typeid(bool)) return Teuchos::any_cast<bool>(any);
        break;
      case ParameterSpec::Type::string:
        if (any.type() == typeid(std::string)) return Teuchos::any_cast<std::string>(any);
        break;
      case ParameterSpec::Type::real_list:
        if (any.type() == typeid(Teuchos::Array<double>)) {
          const auto& a = Teuchos::any_cast<Teuchos::Array<double>>(any);
          return RealList(a.begin(), a.end());
        }
        break;
      case ParameterSpec::Type::string_list:
        if (any.type() == typeid(Teuchos::Array<std::string>)) {
          const auto& a = Teuchos::any_cast<Teuchos::Array<std::string>>(any);
          return StringList(a.begin(), a.end());
        }
        break;
      case ParameterSpec::Type::vector3:
        if (any.type() == typeid(Teuchos::Array<double>)) {
          const auto& a = Teuchos::any_cast<Teuchos::Array<double>>(any);
          if (a.size() == 3) return Vec3(a[0], a[1], a[2]);
          throw Teuchos::Exceptions::InvalidParameterType(
              sublist + "/" + name + ": expected 3 numbers, got " + std::to_string(a.size()));
        }
        break;
    }
    throw Teuchos::Exceptions::InvalidParameterType(sublist + "/" + name + ": expected type " +
                                                    ParameterSpec::type_name(spec_.type) + ", got " +
                                                    teuchos_type_name(entry));
  }

 private:
  ParameterSpec spec_;
};

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(a[i - 1]) == std::tolower(b[j - 1]);
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string unknown_reason(const std::string& name, const std::vector<std::string>& candidates,
                           const char* what) {
  std::string reason = std::string("unknown ") + what;
  const std::string hint = closest_name(name, candidates);
  if (!hint.empty()) reason += " (did you mean '" + hint + "'?)";
  return reason;
}
}  // namespace

std::string closest_name(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(3, name.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

void check_entries(const Teuchos::ParameterList& list, const std::vector<std::string>& allowed_parameters,
                   const std::vector<std::string>& sublists, const std::string& file, const std::string& path) {
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string& name = list.name(it);
    const bool is_list = list.entry(it).isList();
    const auto& allowed = is_list ? sublists : allowed_parameters;
    if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
    std::vector<std::string> all = allowed_parameters;
    all.insert(all.end(), sublists.begin(), sublists.end());
    fail(file, joined(path, name), unknown_reason(name, all, is_list ? "section" : "parameter"));
  }
}

ParameterValues read_parameters(const Teuchos::ParameterList& list, const std::vector<ParameterSpec>& specs,
                                const std::string& file, const std::string& path,
                                const std::vector<std::string>& sublists) {
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  check_entries(list, names, sublists, file, path);
  ParameterValues values;
  for (const auto& spec : specs) {
    if (!list.isParameter(spec.name)) {
      values.set(spec.name, spec.default_value);
      continue;
    }
    const SpecValidator validator(spec);
    const auto& entry = list.getEntry(spec.name);
    try {
      if (entry.isList()) throw Teuchos::Exceptions::InvalidParameterType("/: expected a parameter, got a section");
      validator.validate(entry, spec.name, path);
      values.set(spec.name, validator.value_of(entry, spec.name, path));
    } catch (const std::exception& e) {
      // Teuchos messages carry "sublist/name: " first; keep the reason only.
      std::string reason = e.what();
      const auto colon = reason.find(": ");
      if (colon != std::string::npos) reason = reason.substr(colon + 2);
      fail(file, joined(path, spec.name), reason);
    }
  }
  return values;
}

namespace {
// A whole token as a double; strtod also reads "inf" and "nan", which the range check then names.
bool read_real(const std::string& token, double& x) {
  if (token.empty()) return false;
  char* end = nullptr;
  x = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size();
}

// The items of "{1, 2, 3}" or "1, 2, 3" (braces and commas are separators).
std::vector<std::string> list_items(const std::string& text) {
  std::string cleaned = text;
  for (char& ch : cleaned)
    if (ch == '{' || ch == '}' || ch == ',') ch = ' ';
  std::istringstream in(cleaned);
  std::vector<std::string> items;
  for (std::string item; in >> item;) items.push_back(item);
  return items;
}
}  // namespace

ParameterValue parse_value(const ParameterSpec& spec, const std::string& text) {
  std::istringstream in(text);
  switch (spec.type) {
    case ParameterSpec::Type::real: {
      std::string token;
      double x;
      if (in >> token && (in >> std::ws).eof() && read_real(token, x)) return x;
      break;
    }
    case ParameterSpec::Type::integer: {
      int x;
      if (in >> x && (in >> std::ws).eof()) return x;
      break;
    }
    case ParameterSpec::Type::boolean:
      if (text == "true" || text == "1") return true;
      if (text == "false" || text == "0") return false;
      break;
    case ParameterSpec::Type::string: return text;
    case ParameterSpec::Type::string_list: return list_items(text);
    case ParameterSpec::Type::real_list:
    case ParameterSpec::Type::vector3: {
      RealList list;
      for (const auto& item : list_items(text)) {
        double x;
        if (!read_real(item, x)) throw InputError("cannot read '" + text + "' as " + ParameterSpec::type_name(spec.type));
        list.push_back(x);
      }
      if (spec.type == ParameterSpec::Type::real_list && !list.empty()) return list;
      if (spec.type == ParameterSpec::Type::vector3 && list.size() == 3) return Vec3(list[0], list[1], list[2]);
      break;
    }
  }
  throw InputError("cannot read '" + text + "' as " + ParameterSpec::type_name(spec.type));
}

void set_entry(Teuchos::ParameterList& list, const std::string& name, const ParameterValue& value) {
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, Vec3>) {
          list.set(name, Teuchos::Array<double>(Teuchos::tuple(v[0], v[1], v[2])));
        } else if constexpr (std::is_same_v<T, RealList> || std::is_same_v<T, StringList>) {
          list.set(name, Teuchos::Array<typename T::value_type>(v.begin(), v.end()));
        } else {
          list.set(name, v);
        }
      },
      value);
}

namespace {
// The last non-empty line of a Teuchos exception message (its reason; the lines before name the
// Teuchos source file and the failed test).
std::string teuchos_reason(const std::string& message) {
  std::istringstream in(message);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t-") != std::string::npos) last = line;
  return last.substr(0, 160);
}

// Teuchos reads a number with atof-like leniency ("none" becomes 0) and turns the items of an
// Array(double) that are not finite into 0 ("nan", "inf") or the largest double ("1e400"):
// numbers must be whole tokens, and real ones finite. Empty if `value` is a valid `type`
// (double, int or an array of them, or any other type).
std::string number_problem(const std::string& type, const std::string& value) {
  const bool real = type == "double" || type == "Array(double)";
  const bool integer = type == "int" || type == "Array(int)";
  if (!real && !integer) return {};
  std::vector<std::string> tokens = {value};
  if (type.rfind("Array", 0) == 0) {
    const auto open = value.find('{'), close = value.rfind('}');
    if (open == std::string::npos || close == std::string::npos || close < open)
      return "value '" + value + "' is not a valid " + type + " (e.g. {1, 2, 3})";
    tokens = list_items(value.substr(open + 1, close - open - 1));
    for (auto& token : tokens) token.erase(std::remove(token.begin(), token.end(), ','), token.end());
  }
  for (const auto& token : tokens) {
    char* end = nullptr;
    const std::string trimmed = token.substr(0, token.find_last_not_of(" \t") + 1);
    double x = 0.0;
    if (real) x = std::strtod(trimmed.c_str(), &end);
    else std::strtol(trimmed.c_str(), &end, 10);
    if (trimmed.empty() || end != trimmed.c_str() + trimmed.size())
      return "value '" + value + "' is not a valid " + type;
    if (real && !std::isfinite(x))
      return "value '" + value + (type == "double" ? "' " : "': item '" + trimmed + "' ") + "is not a finite number";
  }
  return {};
}

// The first <Parameter> under `xml` that Teuchos cannot turn into a value (or whose number is
// not a whole number token), as "path/name" and the reason; false if there is none.
bool find_bad_parameter(const Teuchos::XMLObject& xml, const std::string& path, std::string& where, std::string& why) {
  for (int i = 0; i < xml.numChildren(); ++i) {
    const Teuchos::XMLObject& child = xml.getChild(i);
    const std::string name = child.hasAttribute("name") ? child.getAttribute("name") : "?";
    if (child.getTag() == "ParameterList") {
      if (find_bad_parameter(child, joined(path, name), where, why)) return true;
    } else if (child.getTag() == "Parameter") {
      const std::string problem = number_problem(child.hasAttribute("type") ? child.getAttribute("type") : "",
                                                 child.hasAttribute("value") ? child.getAttribute("value") : "");
      if (!problem.empty()) {
        where = joined(path, name);
        why = problem;
        return true;
      }
      Teuchos::XMLObject alone("ParameterList");
      alone.addChild(child);
      try {
        Teuchos::XMLParameterListReader().toParameterList(alone);
      } catch (const std::exception&) {
        const std::string type = child.hasAttribute("type") ? child.getAttribute("type") : std::string();
        where = joined(path, name);
        why = "value '" + (child.hasAttribute("value") ? child.getAttribute("value") : std::string()) +
              "' is not a valid " + (type.empty() ? std::string("value (no type)") : type) +
              (type == "bool" ? " (true or false)" : type.rfind("Array", 0) == 0 ? " (e.g. {1, 2, 3})" : "");
        return true;
      }
    }
  }
  return false;
}
}  // namespace

namespace {
std::size_t line_at(const std::string& text, std::size_t position) {
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(position), '\n'));
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
}  // namespace

void check_xml_limits(const std::string& text, const std::string& origin) {
  using L = XmlLimits;
  if (text.size() > L::max_bytes)
    throw InputError(origin + ": larger than the " + std::to_string(L::max_bytes >> 20) +
                     " MiB an XML parameter file may have");
  const std::size_t n = text.size();
  auto too_long = [&](std::size_t start, std::size_t length, const char* what) {
    if (length > L::max_name_length)
      throw InputError(origin + ": line " + std::to_string(line_at(text, start)) + ": " + what + " of " +
                       std::to_string(length) + " characters, more than the " + std::to_string(L::max_name_length) +
                       " an XML parameter file allows");
  };
  // Skips to just after `end` from `from`; n if it never comes (Teuchos then names the damage).
  auto after = [&](std::size_t from, const char* end) {
    const std::size_t at = text.find(end, from);
    return at == std::string::npos ? n : at + std::char_traits<char>::length(end);
  };
  int depth = 0;
  std::size_t i = 0;
  while (i < n) {
    if (text[i] != '<') {
      ++i;
      continue;
    }
    const std::size_t start = i;
    if (text.compare(i, 4, "<!--") == 0) {
      i = after(i + 4, "-->");
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      i = after(i + 9, "]]>");
    } else if (text.compare(i, 2, "<?") == 0) {
      i = after(i + 2, "?>");
    } else if (text.compare(i, 2, "<!") == 0) {
      i = after(i + 2, ">");
    } else if (text.compare(i, 2, "</") == 0) {
      if (depth > 0) --depth;
      i = after(i + 2, ">");
    } else {
      // An element's start: its tag, then attributes until "/>" (empty) or ">" (one level down).
      i += 1;
      const std::size_t tag = i;
      while (i < n && !is_space(text[i]) && text[i] != '>' && text[i] != '/') ++i;
      too_long(start, i - tag, "an element name");
      bool empty = false;
      while (i < n) {
        while (i < n && is_space(text[i])) ++i;
        if (i >= n) break;
        if (text[i] == '>') break;
        if (text[i] == '/') {
          empty = true;
          ++i;
          continue;
        }
        const std::size_t name = i;
        while (i < n && !is_space(text[i]) && text[i] != '=' && text[i] != '>' && text[i] != '/') ++i;
        too_long(name, i - name, "an attribute name");
        const bool is_name = text.compare(name, i - name, "name") == 0;
        while (i < n && is_space(text[i])) ++i;
        if (i >= n || text[i] != '=') continue;
        ++i;
        while (i < n && is_space(text[i])) ++i;
        if (i >= n || (text[i] != '"' && text[i] != '\'')) continue;
        const char quote = text[i++];
        const std::size_t value = i;
        while (i < n && text[i] != quote) ++i;
        if (is_name) too_long(value, i - value, "a name");
        if (i < n) ++i;
        empty = false;  // a '/' before an attribute was no "/>"
      }
      if (i < n) ++i;  // the '>'
      if (!empty && ++depth > L::max_depth)
        throw InputError(origin + ": line " + std::to_string(line_at(text, start)) + ": nested more than " +
                         std::to_string(L::max_depth) + " levels deep, more than an XML parameter file may be");
    }
  }
}

Teuchos::RCP<Teuchos::ParameterList> read_xml_file(const std::string& file) {
  // Read once, at most one byte beyond the limit (a device or a FIFO is not read to its end), and
  // checked before Teuchos sees it.
  std::error_code error;
  if (std::filesystem::is_directory(file, error)) throw InputError(file + ": is a directory, not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in.good()) throw InputError(file + ": cannot open file");
  std::string text(XmlLimits::max_bytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw InputError(file + ": cannot read file");
  check_xml_limits(text, file);
  Teuchos::XMLObject xml;
  try {
    xml = Teuchos::StringInputSource(text).getObject();
  } catch (const std::exception& e) {
    throw InputError(file + ": not a valid XML file (" + teuchos_reason(e.what()) + ")");
  }
  if (xml.getTag() != "ParameterList") throw InputError(file + ": not a parameter list (<" + xml.getTag() + ">)");
  std::string where, why;
  if (find_bad_parameter(xml, "", where, why)) fail(file, where, why);
  try {
    return Teuchos::rcp(new Teuchos::ParameterList(Teuchos::XMLParameterListReader().toParameterList(xml)));
  } catch (const std::exception& e) {
    throw InputError(file + ": not a valid XML parameter list (" + teuchos_reason(e.what()) + ")");
  }
}

}  // namespace viscompm::params
