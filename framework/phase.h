// The phases of a step, in order (World::Step, framework/README.md): the one
// list that the step's timing (`swarmsim bench`, summary.json), the modules'
// hooks (module.h) and the plugins' phase callbacks (plugin_api.h's
// SwarmsimPhase, mapped onto it when a plugin registers) are named by.
#pragma once

#include <cstddef>
#include <cstdint>

namespace swarmsim {

enum class Phase : uint8_t {
  kSense,    // sensors read the state the last physics step left
  kControl,  // the robots' scripts and controllers
  kActuate,  // deferred writes, calculation modules (IK), joint motion
  kPhysics,  // the dynamics backend steps; modules' hooks run after it
  kRecord,   // metrics, outputs
  kCount
};
inline constexpr size_t kPhaseCount = static_cast<size_t>(Phase::kCount);
const char* ToString(Phase phase);  // "sense", ...
constexpr uint32_t PhaseBit(Phase phase) { return 1u << static_cast<unsigned>(phase); }

// Where within its phase a plugin's callback runs: before the phase's own
// work (before_control) or after it (after_sense, after_control,
// after_physics, record).
enum class PhaseEdge : uint8_t { kStart, kEnd };

}  // namespace swarmsim
