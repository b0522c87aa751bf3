#include "modules/rendering/video/frame_geometry.h"

#include <algorithm>
#include <cmath>

#include "framework/scene.h"

namespace swarmsim::video {

int SegmentsFor(const rendering::View& view) {
  if (!view.orthographic) return 16;
  const double radius = 0.1 * view.width / view.ortho_width;  // pixels
  if (radius <= 0.5) return 6;
  return std::clamp(static_cast<int>(std::ceil(M_PI / std::acos(1 - 0.5 / radius))), 6, 16);
}

void MarkClosed(const Scene& scene, const rendering::DrawList& list, std::vector<uint8_t>* closed) {
  const auto shapes = scene.shapes();
  closed->resize(list.items.size());
  for (size_t i = 0; i < list.items.size(); ++i) {
    const uint32_t slot = list.items[i].slot;
    (*closed)[i] =
        slot == rendering::kNoSlot || (scene.type_at(slot) == ObjectType::kShape &&
                                       shapes[scene.row_at(slot)].kind != ShapeKind::kMesh);
  }
}

void DropHiddenFaces(const rendering::View& view, const std::vector<uint8_t>& closed,
                     rendering::DrawList* list) {
  const Vec3 axis = view.pose.q.Rotate({1, 0, 0});  // where the view looks
  const float ax = static_cast<float>(axis.x), ay = static_cast<float>(axis.y),
              az = static_cast<float>(axis.z);
  const float ex = static_cast<float>(view.pose.p.x), ey = static_cast<float>(view.pose.p.y),
              ez = static_cast<float>(view.pose.p.z);
  std::vector<float>& xyz = list->xyz;
  std::vector<float>& normal = list->normal;
  std::vector<uint8_t>& rgb = list->rgb;
  uint32_t out = 0;  // vertices kept so far
  size_t kept_items = 0;
  for (size_t i = 0; i < list->items.size(); ++i) {
    rendering::DrawItem item = list->items[i];
    const uint32_t first = out;
    for (uint32_t v = item.first; v + 3 <= item.first + item.count; v += 3) {
      const float* a = &xyz[3 * v];
      bool keep = closed[i] == 0;
      if (!keep) {
        const float* b = a + 3;
        const float* c = a + 6;
        const float ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
        const float vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
        const float nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        // From the eye to the triangle: the view's axis (orthographic), or the ray to it.
        const float dx = view.orthographic ? ax : a[0] - ex;
        const float dy = view.orthographic ? ay : a[1] - ey;
        const float dz = view.orthographic ? az : a[2] - ez;
        const float facing = nx * dx + ny * dy + nz * dz;  // < 0: toward the eye
        const float scale =
            std::sqrt((nx * nx + ny * ny + nz * nz) * (dx * dx + dy * dy + dz * dz));
        keep = facing < -1e-4f * scale;
      }
      if (!keep) continue;
      if (out != v) {
        std::copy_n(&xyz[3 * v], 9, &xyz[3 * out]);
        std::copy_n(&normal[3 * v], 9, &normal[3 * out]);
        std::copy_n(&rgb[3 * v], 9, &rgb[3 * out]);
      }
      out += 3;
    }
    item.first = first;
    item.count = out - first;
    if (item.count > 0) list->items[kept_items++] = item;
  }
  list->items.resize(kept_items);
  xyz.resize(3 * static_cast<size_t>(out));
  normal.resize(3 * static_cast<size_t>(out));
  rgb.resize(3 * static_cast<size_t>(out));
}

}  // namespace swarmsim::video
