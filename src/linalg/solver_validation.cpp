// Ifpack2, Amesos2 and MueLu's interpreter are only instantiated here (slow headers).
#include "solver_validation.hpp"

#include <Amesos2_Factory.hpp>
#include <Ifpack2_AdditiveSchwarz.hpp>
#include <Ifpack2_Factory.hpp>
#include <Ifpack2_Parameters.hpp>
#include <Ifpack2_Relaxation.hpp>
#include <MueLu_MasterList.hpp>
#include <MueLu_ParameterListInterpreter.hpp>
#include <Teuchos_DefaultComm.hpp>
#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "linalg_types.hpp"
#include "viscompm/params/parameter_io.hpp"

namespace viscompm::linalg {

namespace {

[[noreturn]] void fail(const std::string& origin, const std::string& path, const std::string& reason) {
  throw parameter_error(origin, path, reason);
}

std::string joined(const std::string& path, const std::string& name) { return path.empty() ? name : path + "/" + name; }

std::vector<std::string> names_of(const Teuchos::ParameterList& list) {
  std::vector<std::string> names;
  for (auto it = list.begin(); it != list.end(); ++it) names.push_back(list.name(it));
  return names;
}

std::string hint(const std::string& name, const std::vector<std::string>& candidates) {
  const std::string best = params::closest_name(name, candidates);
  return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

std::string type_name(const Teuchos::ParameterEntry& entry) {
  if (entry.isList()) return "a sublist";
  const auto& any = entry.getAny(false);
  if (any.type() == typeid(double)) return "double";
  if (any.type() == typeid(int)) return "int";
  if (any.type() == typeid(long long)) return "long long";
  if (any.type() == typeid(bool)) return "bool";
  if (any.type() == typeid(std::string)) return "string";
  return any.typeName();
}

std::string value_text(const Teuchos::ParameterEntry& entry) {
  std::ostringstream out;
  entry.leftshift(out, false);
  return out.str();
}

// The last non-empty line of a (Trilinos, multi-line) exception message, at most 200 characters.
std::string last_line(const std::string& message) {
  std::istringstream in(message);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t") != std::string::npos) last = line;
  last.erase(0, last.find_first_not_of(" \t"));
  return last.substr(0, 200);
}

// Every double of `list` (sublists too) is a finite number.
void check_finite(const Teuchos::ParameterList& list, const std::string& origin, const std::string& path) {
  for (auto it = list.begin(); it != list.end(); ++it) {
    const auto& entry = list.entry(it);
    const std::string where = joined(path, list.name(it));
    if (entry.isList()) {
      check_finite(Teuchos::getValue<Teuchos::ParameterList>(entry), origin, where);
    } else if (entry.getAny(false).type() == typeid(double)) {
      const double x = Teuchos::any_cast<double>(entry.getAny(false));
      if (!std::isfinite(x)) fail(origin, where, "value " + value_text(entry) + " is not a finite number");
    }
  }
}

// Names and types of `given` against `valid` (a library's list of valid parameters), and values
// against the validators it carries. Sublists named in `free_sublists` are not looked into.
void check_against(const Teuchos::ParameterList& given, const Teuchos::ParameterList& valid, const std::string& origin,
                   const std::string& path, const std::vector<std::string>& free_sublists = {}) {
  const std::vector<std::string> candidates = names_of(valid);
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string& name = given.name(it);
    const auto& entry = given.entry(it);
    const std::string where = joined(path, name);
    if (std::find(free_sublists.begin(), free_sublists.end(), name) != free_sublists.end() && entry.isList()) continue;
    const Teuchos::ParameterEntry* valid_entry = valid.getEntryPtr(name);
    if (valid_entry == nullptr) fail(origin, where, "unknown parameter" + hint(name, candidates));
    if (entry.isList() != valid_entry->isList() ||
        (!entry.isList() && entry.getAny(false).type() != valid_entry->getAny(false).type()))
      fail(origin, where, "expected " + type_name(*valid_entry) + ", got " + type_name(entry) +
                              (entry.isList() ? "" : " (" + value_text(entry) + ")"));
    const auto validator = valid_entry->validator();
    if (entry.isList() || validator.is_null()) continue;
    try {
      validator->validate(entry, name, path);
    } catch (const std::exception&) {
      std::string reason = "value '" + value_text(entry) + "' is not valid";
      if (const auto strings = validator->validStringValues(); !strings.is_null()) {
        reason += hint(value_text(entry), std::vector<std::string>(strings->begin(), strings->end()));
        if (reason.find("did you mean") == std::string::npos) {
          reason += " (one of:";
          for (const auto& s : *strings) reason += " '" + s + "'";
          reason += ")";
        }
      }
      fail(origin, where, reason);
    }
  }
}

// Maps an exception thrown by a library's own checks (setParameters, the MueLu interpreter) to the
// parameter of `given` its message names, or to `path` itself.
[[noreturn]] void fail_from_library(const std::exception& e, const Teuchos::ParameterList& given,
                                    const std::string& origin, const std::string& path) {
  const std::string message = e.what();
  std::string named;
  for (const auto& name : names_of(given))
    if (message.find("\"" + name + "\"") != std::string::npos && name.size() > named.size()) named = name;
  // Else the parameter whose value the message quotes (e.g. Unknown aggregation algorithm: "x").
  if (named.empty())
    for (auto it = given.begin(); it != given.end(); ++it)
      if (given.entry(it).isType<std::string>() &&
          message.find("\"" + Teuchos::getValue<std::string>(given.entry(it)) + "\"") != std::string::npos)
        named = given.name(it);
  fail(origin, named.empty() ? path : joined(path, named), last_line(message));
}

// The names Ifpack2 accepts in some preconditioner's list (its global list of valid parameters,
// plus the inner-solver names AdditiveSchwarz reads that the list omits).
const Teuchos::ParameterList& ifpack2_names() {
  static const Teuchos::ParameterList valid = [] {
    Teuchos::ParameterList v;
    Ifpack2::getValidParameters(v);
    for (const char* name : {"inner preconditioner name", "subdomain solver name", "schwarz: inner preconditioner name",
                             "schwarz: subdomain solver name"})
      v.set(name, std::string());
    for (const char* name : {"inner preconditioner parameters", "subdomain solver parameters",
                             "schwarz: inner preconditioner parameters", "schwarz: subdomain solver parameters"})
      v.sublist(name);
    return v;
  }();
  return valid;
}

// Ifpack2 and MueLu bound none of the counts that set the work of one preconditioner set-up or
// application: 2^31 sweeps or levels keep one Newton step busy for hours, deaf to a stop signal
// (found by fuzzing). These caps are far above any useful value.
void check_work_counts(const Teuchos::ParameterList& given, const std::string& origin, const std::string& path) {
  static const std::pair<const char*, int> caps[] = {
      {"relaxation: sweeps", 1000},      {"smoother: sweeps", 1000},
      {"chebyshev: degree", 1000},       {"chebyshev: eigenvalue max iterations", 1000},
      {"sa: eigenvalue estimate num iterations", 1000},
      {"fact: iluk level-of-fill", 100}, {"schwarz: overlap level", 100},
      {"max levels", 31},  // each level halves the grid; no grid has 2^31 cells across
  };
  for (const auto& [name, cap] : caps)
    if (given.isType<int>(name) && given.get<int>(name) > cap)
      fail(origin, joined(path, name),
           "value " + std::to_string(given.get<int>(name)) + " is more than " + std::to_string(cap) +
               ", more work per preconditioner set-up or application than can be useful");
}

// A string parameter that must be one of `words`, when the library checks it too late.
void check_word(const Teuchos::ParameterList& given, const std::string& name, const std::vector<std::string>& words,
                const std::string& origin, const std::string& path) {
  if (!given.isType<std::string>(name)) return;
  const std::string value = given.get<std::string>(name);
  if (std::find(words.begin(), words.end(), value) != words.end()) return;
  std::string list;
  for (const auto& word : words) list += (list.empty() ? "'" : ", '") + word + "'";
  fail(origin, joined(path, name), "'" + value + "' is not one of " + list + hint(value, words));
}
}  // namespace

void validate_krylov_parameters(const Teuchos::ParameterList& given, const Teuchos::ParameterList& valid,
                                const std::string& origin, const std::string& path) {
  check_finite(given, origin, path);
  check_against(given, valid, origin, path);
  // Belos declares no validators: a tolerance ≤ 0 or ≥ 1 or no iterations make CG run for ever
  // or not at all.
  if (given.isType<double>("Convergence Tolerance")) {
    const double tolerance = given.get<double>("Convergence Tolerance");
    if (!(tolerance > 0.0 && tolerance < 1.0))
      fail(origin, joined(path, "Convergence Tolerance"), "value " + value_text(given.getEntry("Convergence Tolerance")) +
                                                               " is out of range (0, 1)");
  }
  for (const char* name : {"Maximum Iterations", "Block Size", "Num Blocks", "Maximum Restarts"})
    if (given.isType<int>(name) && given.get<int>(name) < 1)
      fail(origin, joined(path, name), "value " + std::to_string(given.get<int>(name)) + " is out of range [1, inf]");
}

void validate_ifpack2_parameters(const std::string& type, const Teuchos::ParameterList& given, const std::string& origin,
                                 const std::string& type_parameter, const std::string& path) {
  if (!Ifpack2::Factory::isSupported<crs_matrix_type>(type))
    fail(origin, type_parameter,
         "'" + type + "' is not an Ifpack2 preconditioner" +
             hint(type, {"RELAXATION", "CHEBYSHEV", "BLOCK_RELAXATION", "ILUT", "RILUK", "SCHWARZ", "DIAGONAL"}));
  check_finite(given, origin, path);
  check_against(given, ifpack2_names(), origin, path);
  check_work_counts(given, origin, path);
  // Words Ifpack2 13.2 checks only once it has a matrix (BlockRelaxation::initialize).
  check_word(given, "partitioner: type", {"linear", "line", "user"}, origin, path);
  // AdditiveSchwarz creates its inner solver by name only in initialize() (found by fuzzing).
  for (const char* name : {"inner preconditioner name", "subdomain solver name", "schwarz: inner preconditioner name",
                           "schwarz: subdomain solver name"})
    if (given.isType<std::string>(name) &&
        !Ifpack2::Factory::isSupported<crs_matrix_type>(given.get<std::string>(name)))
      fail(origin, joined(path, name),
           "'" + given.get<std::string>(name) + "' is not an Ifpack2 preconditioner" +
               hint(given.get<std::string>(name), {"AMESOS2", "RILUK", "ILUT", "RELAXATION", "CHEBYSHEV", "DENSE"}));
  // The preconditioner of that type, without a matrix, checks the values itself: its list of
  // valid parameters with validators where it has one, and setParameters.
  Teuchos::RCP<ifpack2_preconditioner_type> prec;
  try {
    prec = Ifpack2::Factory::create<row_matrix_type>(type, Teuchos::null);
  } catch (const std::exception&) {
    return;  // this type cannot exist without a matrix: names were checked above
  }
  Teuchos::RCP<const Teuchos::ParameterList> valid;
  if (auto* r = dynamic_cast<Ifpack2::Relaxation<row_matrix_type>*>(prec.get())) valid = r->getValidParameters();
  if (auto* s = dynamic_cast<Ifpack2::AdditiveSchwarz<row_matrix_type>*>(prec.get())) {
    // AdditiveSchwarz reads its inner solver's names and list without listing them as valid.
    auto with_inner = Teuchos::rcp(new Teuchos::ParameterList(*s->getValidParameters()));
    const Teuchos::ParameterList& names = ifpack2_names();
    for (const char* name : {"inner preconditioner name", "subdomain solver name", "schwarz: inner preconditioner name",
                             "schwarz: subdomain solver name", "inner preconditioner parameters",
                             "subdomain solver parameters", "schwarz: inner preconditioner parameters",
                             "schwarz: subdomain solver parameters"})
      if (!with_inner->isParameter(name)) with_inner->setEntry(name, names.getEntry(name));
    valid = with_inner;
  }
  if (!valid.is_null()) check_against(given, *valid, origin, path, {"inner preconditioner parameters",
                                                                    "subdomain solver parameters",
                                                                    "schwarz: inner preconditioner parameters",
                                                                    "schwarz: subdomain solver parameters"});
  try {
    prec->setParameters(given);
  } catch (const std::exception& e) {
    fail_from_library(e, given, origin, path);
  }
}

void validate_muelu_parameters(const Teuchos::ParameterList& given, const std::string& origin, const std::string& path) {
  check_finite(given, origin, path);
  const Teuchos::ParameterList& master = *MueLu::MasterList::List();
  // Level sublists ("level 1", ...) take the same names; "user data" holds what viscompm adds.
  std::vector<std::string> levels;
  for (const auto& name : names_of(given))
    if (name.rfind("level ", 0) == 0 && given.isSublist(name)) levels.push_back(name);
  std::vector<std::string> free = levels;
  free.push_back("user data");
  check_against(given, master, origin, path, free);
  for (const auto& level : levels) check_against(given.sublist(level), master, origin, joined(path, level), {"user data"});

  // Smoothers and the coarse solver: Ifpack2 preconditioners (their parameter sublists are Ifpack2
  // lists of that type) or, for the coarse level, Amesos2 direct solvers.
  const std::vector<std::pair<std::string, std::string>> solvers = {{"smoother: type", "smoother: params"},
                                                                    {"smoother: pre type", "smoother: pre params"},
                                                                    {"smoother: post type", "smoother: post params"},
                                                                    {"coarse: type", "coarse: params"}};
  for (const auto& [type_name_parameter, params_name] : solvers) {
    if (!given.isType<std::string>(type_name_parameter)) continue;
    const std::string type = given.get<std::string>(type_name_parameter);
    const bool coarse = type_name_parameter == "coarse: type";
    if (Ifpack2::Factory::isSupported<crs_matrix_type>(type)) {
      // MueLu's Ifpack2 smoother takes a few keys out of the list before Ifpack2 sees it
      // (MueLu_Ifpack2Smoother_def.hpp, Trilinos 13.2; MueLu does not list them anywhere).
      Teuchos::ParameterList ifpack2_list = given.isSublist(params_name) ? given.sublist(params_name) : Teuchos::ParameterList();
      for (const char* muelu_key : {"smoother: use blockcrsmatrix storage", "smoother: neighborhood type",
                                    "pcoarsen: hi basis", "chebyshev: use rowsumabs diagonal scaling",
                                    "chebyshev: rowsumabs diagonal replacement tolerance",
                                    "chebyshev: rowsumabs diagonal replacement value"})
        ifpack2_list.remove(muelu_key, false);
      validate_ifpack2_parameters(type, ifpack2_list, origin, joined(path, type_name_parameter), joined(path, params_name));
    } else if (!(coarse && Amesos2::query(type))) {
      fail(origin, joined(path, type_name_parameter),
           "'" + type + "' is not an Ifpack2 preconditioner" + (coarse ? " or an Amesos2 solver" : "") +
               hint(type, {"RELAXATION", "CHEBYSHEV", "BLOCK RELAXATION", "ILUT", "RILUK", "SCHWARZ", "KLU2"}));
    }
  }

  check_work_counts(given, origin, path);
  // Checked by MueLu only when the hierarchy is set up (MueLu::toVerbLevel).
  check_word(given, "verbosity", {"none", "low", "medium", "high", "extreme", "test"}, origin, path);
  for (const auto& level : levels) check_work_counts(given.sublist(level), origin, joined(path, level));
  if (given.isType<int>("max levels") && given.get<int>("max levels") < 1)
    fail(origin, joined(path, "max levels"), "value " + std::to_string(given.get<int>("max levels")) + " is out of range [1, 31]");

  // MueLu's interpreter checks the values it knows (algorithms, aggregation and reuse types, ...).
  Teuchos::ParameterList copy = given;
  copy.remove("user data", false);
  copy.set("verbosity", std::string("none"));
  try {
    muelu_interpreter_type interpreter(
        copy, Teuchos::DefaultComm<int>::getComm());
  } catch (const std::exception& e) {
    fail_from_library(e, given, origin, path);
  }
}

}  // namespace viscompm::linalg
