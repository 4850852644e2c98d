#pragma once
// A job's parameters as flat columns: nested JSON objects become dotted names, so the
// canonical {"depth": 2, "overrides": {"shell.cloth.material.thickness": 5e-4}} gives the
// columns "depth" and "overrides.shell.cloth.material.thickness".

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace psq::reports {

/// Every leaf of `parameters` (numbers, strings, booleans, null, arrays) by its dotted path.
/// A value that is not an object is returned under the name "value".
std::map<std::string, nlohmann::json> flatten_parameters(const nlohmann::json& parameters);

/// The names, sorted, whose value differs between any two of the parameter sets (a name absent
/// from some set counts as differing).
std::vector<std::string> varying_parameters(
    const std::vector<std::map<std::string, nlohmann::json>>& parameter_sets);

/// A short text of `value` that reads back to the same double: "0.001", "40", "2e+09".
std::string exact_text(double value);

/// The last part of a dotted parameter name: "overrides.shell.strip.material.thickness" →
/// "thickness".
std::string short_name(const std::string& name);

/// "thickness=0.001, youngs_modulus=2e+09": the values of `names` in `parameters` (cell_text,
/// "-" for a missing one) by their short names.
std::string parameter_values(const std::map<std::string, nlohmann::json>& parameters,
                             const std::vector<std::string>& names);

/// A value as a table cell: strings without quotes, integers as such, other numbers as
/// exact_text, anything else as compact JSON; empty for a missing value.
std::string cell_text(const nlohmann::json& value);

}  // namespace psq::reports
