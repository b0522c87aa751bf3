#include "framework/sensor_noise.h"

#include <string>

#include "framework/number_rule.h"
#include "framework/object_type.h"

namespace swarmsim {

void ReadNoise(const ObjectReader& r, std::string_view prefix, double max, NoiseSettings* out) {
  const NumberRule width{"a non-negative number", 0, max};
  const std::string p(prefix);
  if (r.Has(p + "noise")) out->gaussian = r.Number(p + "noise", width);
  if (r.Has(p + "noise_uniform")) out->uniform = r.Number(p + "noise_uniform", width);
  if (r.Has(p + "failure_probability"))
    out->failure = r.Number(p + "failure_probability", kFraction);
}

}  // namespace swarmsim
