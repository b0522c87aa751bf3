// Named parameters: world parameters and per-model-instance parameters.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <variant>

namespace swarmsim {

using ParamValue = std::variant<double, bool, std::string>;

// Exact text of a value (numbers with 17 digits): what the state hash adds.
std::string ParamToString(const ParamValue& value);
// A value as a user writes it, for messages and listings: the shortest text
// that reads back to the same number (0.05, not 0.050000000000000003).
std::string ShowParamValue(const ParamValue& value);

// An ordered name -> value map. Instances of one model share one set until
// one of them is given its own values.
using ParameterSet = std::map<std::string, ParamValue, std::less<>>;
using SharedParameters = std::shared_ptr<const ParameterSet>;

}  // namespace swarmsim
