// Named parameters: world parameters and per-model-instance parameters.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <variant>

namespace swarmsim {

using ParamValue = std::variant<double, bool, std::string>;

std::string ParamToString(const ParamValue& value);

// An ordered name -> value map. Instances of one model share one set until
// one of them is given its own values.
using ParameterSet = std::map<std::string, ParamValue, std::less<>>;
using SharedParameters = std::shared_ptr<const ParameterSet>;

}  // namespace swarmsim
