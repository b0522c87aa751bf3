// The `led` object type's row: a coloured light on a robot (ARGoS's LED
// equipped entity), seen by blob cameras (blob_camera.h). The recorder, the
// renderer and the viewer draw it through its type's visual (objects.cc: a
// light, framework/visual.h), not through this row.
//
// Public: code outside modules/blobs finds the type by name and casts its
// table (no link dependency on this module):
//   ObjectType led;
//   if (scene.FindType(kLedTypeName, &led))
//     for (const LedRow& row : static_cast<const Rows<LedRow>&>(*scene.rows(led)).rows) ...
// Row r belongs to the object at slot rows.owners[r]; the LED sits at that
// object's origin (Scene::world_pose_at).
//
// Scripts change an LED in the control phase (its own robot's scripts, or
// the scene's); cameras and renderers read it in the sense phase, so they
// see what the scripts left at the end of the last step.
#pragma once

#include "framework/math.h"

namespace swarmsim {

inline constexpr const char* kLedTypeName = "led";

struct LedRow {          // 40 bytes
  Vec3 color{1, 1, 1};   // RGB, each 0..1
  double radius = 0.01;  // m: how big it is drawn (a sphere); cameras see its centre
  bool on = true;        // switched on
  // Does it emit light (on, and not black, as ARGoS has it)? Cameras see
  // only lit LEDs.
  bool lit() const { return on && (color.x > 0 || color.y > 0 || color.z > 0); }
};

}  // namespace swarmsim
