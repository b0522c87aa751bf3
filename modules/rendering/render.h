// Drawing the scene from a viewpoint (modules/rendering, on OSMesa): what
// cameras, vision sensors, snapshots and the video writer share. No OpenGL
// types here.
//
// A view looks along its frame's +x axis with +z up (the body convention
// of wheeled robots: a camera mounted with the identity pose looks ahead);
// the image's x runs to the view's -y (right), its rows top to bottom.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "framework/image.h"
#include "framework/math.h"

namespace swarmsim {
class World;
}

namespace swarmsim::rendering {

struct View {
  Pose pose;  // world frame
  bool orthographic = false;
  double fov = 1.0471975511965976;  // rad, horizontal (perspective)
  double ortho_width = 1;           // m the image spans horizontally (orthographic)
  double near = 0.01;               // m, clipping planes
  double far = 20;
  int width = 640;
  int height = 480;
  bool depth = false;  // also fill Image::depth (metres along the view axis; far where nothing)
};

// Draws `world`'s scene as `view` sees it into *image: shapes in their
// colours, LEDs (at least 3 pixels wide in an orthographic view), lights (a
// sun and a headlight when the scene has no light objects), the floor
// with the paint layer. Thread-safe (one GL context per calling thread);
// the same scene and view give the same bytes whatever the thread.
// Throws swarmsim::Error when OSMesa cannot make a context.
void Render(const World& world, const View& view, Image* image);

// A top-down orthographic view framed on the arena (every shape and the
// environment map, with a margin), `width` x `height` pixels.
View ArenaView(const World& world, int width, int height);

// The view of the camera or vision sensor object `path` ("/camera",
// "footbot#3/cam", or a unique name), at its own resolution; nullopt and
// *error set when there is none.
std::optional<View> CameraView(const World& world, std::string_view path, std::string* error);

}  // namespace swarmsim::rendering
