// modules/blobs: coloured LEDs on robots and the blob camera that sees them
// without rasterising (ARGoS's LED entity and colored blob omnidirectional
// camera): the `led` and `blob_camera` object types (leds.h,
// blob_camera.h), the camera module (sense phase, robots' cameras in
// parallel), the scripts' sim.setLedColor, sim.getLedColor, sim.setLedOn,
// sim.readBlobCamera, and two swarm metrics of colour clustering
// (same_color_neighbor_fraction, color_dispersion).
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::blobs {

// The camera module, its two object types and the two metrics.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::blobs
