// The triangles of a video frame: the renderer's draw list
// (modules/rendering/geometry.h) trimmed to what a view can show, for the
// recorder (recorder.cc). A frame of a thousand robots spends most of its
// time in Mesa's vertex stage, so fewer triangles is most of the gain.
#pragma once

#include <cstdint>
#include <vector>

#include "modules/rendering/geometry.h"

namespace swarmsim {
class Scene;
}

namespace swarmsim::video {

// Sides of cylinders (and slices of spheres) for `view`: as many as keep a
// circle of a swarm robot's radius (0.1 m) within half a pixel of round,
// from 6 (a thousand robots from above at 640x480) to 16 (a perspective
// camera, as vision sensors draw).
int SegmentsFor(const rendering::View& view);

// Per item of `list`: 1 when it is a closed primitive (a shape other than
// a mesh, an environment box), whose faces turned away from the eye are
// hidden behind its others.
void MarkClosed(const Scene& scene, const rendering::DrawList& list, std::vector<uint8_t>* closed);

// Drops the triangles of closed items that face away from the eye of
// `view` or are seen edge-on (OpenGL's back-face culling, done before
// Mesa's vertex stage): seen from above, an upright cylinder keeps its top.
void DropHiddenFaces(const rendering::View& view, const std::vector<uint8_t>& closed,
                     rendering::DrawList* list);

}  // namespace swarmsim::video
