// Reading declared parameters (core/parameters.hpp) out of Teuchos parameter lists: unknown or
// misspelled names, wrong types, and out-of-range values end the run at read
// time with one line naming the file and the parameter path. The layer below both the scene
// reader and the solver configurations (doc/architecture.md): it includes only core/ and Teuchos.
#pragma once

#include <Teuchos_ParameterList.hpp>
#include <cstddef>
#include <string>
#include <vector>

#include "viscompm/core/parameters.hpp"

namespace viscompm::params {

/// Reads the entries of `list` (the section at `path` of `file`). Every entry must be declared
/// in `specs`, or be a sublist named in `sublists`. Missing entries take their defaults.
ParameterValues read_parameters(const Teuchos::ParameterList& list, const std::vector<ParameterSpec>& specs,
                                const std::string& file, const std::string& path,
                                const std::vector<std::string>& sublists = {});

/// Checks that every sublist of `list` is one of `sublists` and that there are no parameters
/// besides `allowed_parameters`.
void check_entries(const Teuchos::ParameterList& list, const std::vector<std::string>& allowed_parameters,
                   const std::vector<std::string>& sublists, const std::string& file, const std::string& path);

/// Parses `text` as a value of the spec's type ("{1, 2, 3}" or "1, 2, 3" for vectors).
ParameterValue parse_value(const ParameterSpec& spec, const std::string& text);
/// Sets entry `name` of `list` to `value` with the Teuchos type of the value.
void set_entry(Teuchos::ParameterList& list, const std::string& name, const ParameterValue& value);
/// The bounds an XML parameter file keeps before Teuchos parses it. Teuchos' parser and list
/// reader recurse once per nesting level and keep every name whole, so a deep or huge file from a
/// broken generator would overflow the stack instead of being answered. The shipped files are at
/// most 7 kB, 5 levels deep and 47 characters per name (doc/inputs.md).
struct XmlLimits {
  static constexpr std::size_t max_bytes = std::size_t{4} << 20;  // 4 MiB
  static constexpr int max_depth = 32;                             // nested elements
  static constexpr std::size_t max_name_length = 256;              // tag, attribute and name="..." values
};
/// Checks `text` (the contents of `origin`) against XmlLimits without recursion; InputError
/// "ORIGIN: ..." naming the limit (and the line) if it breaks one.
void check_xml_limits(const std::string& text, const std::string& origin);
/// Reads an XML parameter list file (scene, solver or study file: the one reader of them all);
/// InputError if it is missing, malformed or beyond XmlLimits.
Teuchos::RCP<Teuchos::ParameterList> read_xml_file(const std::string& file);
/// The closest of `candidates` to `name` by edit distance (for "did you mean" hints), or "".
std::string closest_name(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace viscompm::params
