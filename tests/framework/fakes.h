// Test doubles for framework tests that need a World but not real modules.
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "modules/proximity/proximity.h"

namespace swarmsim::testing {

// Moves nothing.
class NullDynamics : public DynamicsBackend {
 public:
  void Build(const Scene&, const DynamicsSettings&) override {}
  void Step(Scene*, double, int) override {}
  int body_count() const override { return 0; }
};

// Detects nothing.
class NullProximity : public ProximityBackend {
 public:
  void Build(const Scene&, const ProximitySettings&) override {}
  void Update(const Scene&) override {}
  void SenseInstance(Scene*, int) const override {}
  void SenseSceneSensors(Scene*) const override {}
};

// A registry with "null" dynamics and "proximity" (null) modules, the
// latter with the proximity_sensor type and its Lua area
// (modules/proximity: framework tests link it for that).
inline ModuleRegistry NullRegistry() {
  ModuleRegistry r;
  r.RegisterDynamics({"", "null", "1", "moves nothing"}, {.substeps = false},
                     [] { return std::make_unique<NullDynamics>(); });
  proximity::Register(&r, {"", "proximity", "1", "detects nothing"},
                      [] { return std::make_unique<NullProximity>(); });
  return r;
}

}  // namespace swarmsim::testing
