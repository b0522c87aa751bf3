#include "modules/force_sensor/force_sensor.h"

#include <algorithm>

namespace swarmsim {

bool RecordForceSensorSample(ForceSensorData* s, const Vec3& force_S, const Vec3& torque_S) {
  if (s->broken) return false;
  const size_t n = static_cast<size_t>(std::max(1, s->filter_samples));
  s->has_reading = true;
  if (n == 1) {
    s->force = force_S;
    s->torque = torque_S;
  } else {
    // Mean of the last n samples (fewer until the ring is full), summed in
    // ring order so the result does not depend on anything but the samples.
    if (s->force_samples.size() < n && s->next_sample == s->force_samples.size()) {
      s->force_samples.push_back(force_S);
      s->torque_samples.push_back(torque_S);
    } else {
      s->force_samples[s->next_sample] = force_S;
      s->torque_samples[s->next_sample] = torque_S;
    }
    s->next_sample = static_cast<uint32_t>((s->next_sample + 1) % n);
    Vec3 f, t;
    for (size_t i = 0; i < s->force_samples.size(); ++i) {
      f = f + s->force_samples[i];
      t = t + s->torque_samples[i];
    }
    const double inv = 1.0 / static_cast<double>(s->force_samples.size());
    s->force = f * inv;
    s->torque = t * inv;
  }
  const bool violated =
      s->force.Norm() > s->force_threshold || s->torque.Norm() > s->torque_threshold;
  s->violations = violated ? s->violations + 1 : 0;
  if (s->violations >= std::max(1, s->break_after)) {
    s->broken = true;
    return true;
  }
  return false;
}

}  // namespace swarmsim
