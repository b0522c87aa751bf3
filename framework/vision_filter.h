// Vision-sensor filter elements (CoppeliaSim's filter blocks, paper §2.1):
// what the registry holds of each element a sensor's `filters:` list may
// name. The elements and the chain that runs them live in
// modules/rendering/filters (filters.h); the built-in ones register there,
// a plugin's through plugin_api.h's add_vision_filter (ABI 5), into the same
// list (ModuleRegistry::RegisterVisionFilter).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "framework/plugin_api.h"

namespace swarmsim {

class ObjectReader;
class VisionFilterElement;  // one configured element: modules/rendering/filters/element.h

// One key of an element's list item besides `type`, as worlds/README.md lists it.
struct VisionFilterKey {
  std::string name;
  std::string default_text;  // "required", "[0, 360]", ...
  std::string doc;           // one line: unit and meaning
  // A plugin's keys are numbers in [min, max] (default_value when absent).
  double default_value = 0;
  double min = -std::numeric_limits<double>::max();
  double max = std::numeric_limits<double>::max();
};

struct VisionFilterDescriptor {
  std::string name;             // as model files write it: {type: NAME, ...}
  std::string description;      // one line
  std::string version = "1.0";  // for `swarmsim modules` (a plugin's: its own)
  // The kinds of work image it takes (SwarmsimImageKind bits) and the kind
  // it gives (one bit; 0: the kind it was given).
  uint32_t input = 0;
  uint32_t output = 0;
  std::vector<VisionFilterKey> keys;
  // A module's element, configured from its item of the list (its keys are
  // checked first). Throws swarmsim::Error through the reader.
  std::function<std::shared_ptr<const VisionFilterElement>(const ObjectReader& item)> make;
  // A plugin's element instead (no `make`): the filters module calls
  // `function` with the keys' values in order (plugin_api.h).
  SwarmsimFilterFunction plugin_function = nullptr;
  void* plugin_user_data = nullptr;
  int plugin_max_values = 0;  // numbers its packet holds at most; 0: no packet
};

}  // namespace swarmsim
