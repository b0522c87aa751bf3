#include "modules/rendering/geometry.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

#include "framework/environment.h"
#include "framework/floor_layer.h"
#include "framework/mesh.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/visual.h"
#include "framework/world.h"
#include "modules/rendering/objects.h"

namespace swarmsim::rendering {

namespace {

// A primitive in its own frame: triangles (3 vertices each) with normals,
// and a colour per vertex for meshes with materials.
struct Primitive {
  std::vector<Vec3> p, n;
  std::vector<Vec3> c;  // per vertex, or empty: the shape's colour
};

void AddTriangle(Primitive* m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& na,
                 const Vec3& nb, const Vec3& nc) {
  m->p.insert(m->p.end(), {a, b, c});
  m->n.insert(m->n.end(), {na, nb, nc});
}

void AddQuad(Primitive* m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
             const Vec3& n) {
  AddTriangle(m, a, b, c, n, n, n);
  AddTriangle(m, a, c, d, n, n, n);
}

// The unit box [-0.5, 0.5]^3, counter-clockwise seen from outside.
Primitive UnitBox() {
  Primitive m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      Vec3 n{};
      (&n.x)[axis] = sign;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 c[4];
      const double us[4] = {-0.5, 0.5, 0.5, -0.5}, vs[4] = {-0.5, -0.5, 0.5, 0.5};
      for (int k = 0; k < 4; ++k) {
        (&c[k].x)[axis] = 0.5 * sign;
        (&c[k].x)[u] = us[k];
        (&c[k].x)[v] = vs[k] * sign;
      }
      AddQuad(&m, c[0], c[1], c[2], c[3], n);
    }
  }
  return m;
}

// Radius 1 about z, z from z0 to z1; caps when asked.
void AddTube(Primitive* m, int segments, double z0, double z1, bool caps) {
  for (int i = 0; i < segments; ++i) {
    const double a0 = 2 * M_PI * i / segments, a1 = 2 * M_PI * (i + 1) / segments;
    const Vec3 r0{std::cos(a0), std::sin(a0), 0}, r1{std::cos(a1), std::sin(a1), 0};
    AddTriangle(m, r0 + Vec3{0, 0, z0}, r1 + Vec3{0, 0, z0}, r1 + Vec3{0, 0, z1}, r0, r1, r1);
    AddTriangle(m, r0 + Vec3{0, 0, z0}, r1 + Vec3{0, 0, z1}, r0 + Vec3{0, 0, z1}, r0, r1, r0);
    if (caps) {
      const Vec3 up{0, 0, 1}, down{0, 0, -1};
      AddTriangle(m, Vec3{0, 0, z1}, r0 + Vec3{0, 0, z1}, r1 + Vec3{0, 0, z1}, up, up, up);
      AddTriangle(m, Vec3{0, 0, z0}, r1 + Vec3{0, 0, z0}, r0 + Vec3{0, 0, z0}, down, down, down);
    }
  }
}

// The unit sphere's band of polar angles [t0, t1] (0: +z), moved by dz.
void AddSphereBand(Primitive* m, int segments, int stacks, double t0, double t1, double dz) {
  for (int j = 0; j < stacks; ++j) {
    const double a = t0 + (t1 - t0) * j / stacks, b = t0 + (t1 - t0) * (j + 1) / stacks;
    for (int i = 0; i < segments; ++i) {
      const double p0 = 2 * M_PI * i / segments, p1 = 2 * M_PI * (i + 1) / segments;
      const auto at = [](double t, double p) {
        return Vec3{std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
      };
      const Vec3 v00 = at(a, p0), v01 = at(a, p1), v10 = at(b, p0), v11 = at(b, p1);
      const Vec3 d{0, 0, dz};
      if (j > 0 || t0 > 0) AddTriangle(m, v00 + d, v10 + d, v01 + d, v00, v10, v01);
      if (j < stacks - 1 || t1 < M_PI) AddTriangle(m, v01 + d, v10 + d, v11 + d, v01, v10, v11);
      if (j == 0 && t0 == 0) AddTriangle(m, v00 + d, v10 + d, v11 + d, v00, v10, v11);
      if (j == stacks - 1 && t1 >= M_PI) AddTriangle(m, v00 + d, v10 + d, v11 + d, v00, v10, v11);
    }
  }
}

struct Primitives {
  Primitive box, cylinder, sphere;
  explicit Primitives(int segments) {
    box = UnitBox();
    AddTube(&cylinder, segments, -0.5, 0.5, true);
    AddSphereBand(&sphere, segments, std::max(2, segments / 2), 0, M_PI, 0);
  }
};

const Primitives& PrimitivesFor(int segments) {
  static std::mutex mutex;
  static std::vector<std::pair<int, std::unique_ptr<Primitives>>> cache;
  const std::lock_guard lock(mutex);
  for (const auto& [n, p] : cache)
    if (n == segments) return *p;
  cache.emplace_back(segments, std::make_unique<Primitives>(segments));
  return *cache.back().second;
}

// A capsule of radius r and total height h about z (h >= 2r): built per
// shape (its caps do not scale with the height).
Primitive Capsule(int segments, double r, double h) {
  Primitive m;
  const double half = std::max(0.0, h / 2 - r) / r;  // in radii
  AddTube(&m, segments, -half, half, false);
  AddSphereBand(&m, segments, std::max(1, segments / 4), 0, M_PI / 2, half);
  AddSphereBand(&m, segments, std::max(1, segments / 4), M_PI / 2, M_PI, -half);
  return m;
}

// Flat-shaded triangles of a mesh, in its frame.
Primitive MeshPrimitive(const TriangleMesh& mesh) {
  Primitive m;
  const auto v = mesh.vertices();
  const auto colors = mesh.colors();
  for (size_t i = 0; i < mesh.triangles().size(); ++i) {
    const MeshTriangle& t = mesh.triangles()[i];
    const Vec3 &a = v[t.v[0]], &b = v[t.v[1]], &c = v[t.v[2]];
    const Vec3 n = (b - a).Cross(c - a).Normalized();
    AddTriangle(&m, a, b, c, n, n, n);
    if (!colors.empty()) m.c.insert(m.c.end(), {colors[i], colors[i], colors[i]});
  }
  return m;
}

// The primitive of a mesh asset, made once. Cached by address and checked
// against what the asset holds (sizes, bounds, name): a mesh freed (a
// world gone, a shape scaled to a new mesh) may leave its address to
// another, which must not be drawn as the first.
struct MeshKey {
  const TriangleMesh* mesh;
  size_t vertices, triangles;
  Vec3 lo, hi;
  std::string name;
  explicit MeshKey(const TriangleMesh* m)
      : mesh(m),
        vertices(m->vertices().size()),
        triangles(m->triangles().size()),
        lo(m->lo()),
        hi(m->hi()),
        name(m->name()) {}
  bool Same(const MeshKey& o) const {
    return vertices == o.vertices && triangles == o.triangles && lo == o.lo && hi == o.hi &&
           name == o.name;
  }
};

const Primitive& MeshFor(const TriangleMesh* mesh) {
  static std::mutex mutex;
  static std::vector<std::pair<MeshKey, std::unique_ptr<Primitive>>> cache;
  const std::lock_guard lock(mutex);
  const MeshKey key(mesh);
  for (auto& [k, p] : cache) {
    if (k.mesh != mesh) continue;
    if (!k.Same(key)) {  // another mesh at a freed one's address
      k = key;
      p = std::make_unique<Primitive>(MeshPrimitive(*mesh));
    }
    return *p;
  }
  cache.emplace_back(key, std::make_unique<Primitive>(MeshPrimitive(*mesh)));
  return *cache.back().second;
}

uint8_t Byte(double c) { return static_cast<uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255)); }

// Appends `prim` scaled by `scale` and placed at X_WS.
void Append(DrawList* list, uint32_t slot, const Primitive& prim, const Vec3& scale,
            const Pose& X_WS, const Vec3& color, bool emissive, bool own_colors = false) {
  DrawItem item{};
  item.slot = slot;
  item.first = static_cast<uint32_t>(list->xyz.size() / 3);
  item.count = static_cast<uint32_t>(prim.p.size());
  item.emissive = emissive;
  const uint8_t rgb[3] = {Byte(color.x), Byte(color.y), Byte(color.z)};
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi = -lo;
  for (size_t i = 0; i < prim.p.size(); ++i) {
    const Vec3& p0 = prim.p[i];
    const Vec3 p = X_WS * Vec3{p0.x * scale.x, p0.y * scale.y, p0.z * scale.z};
    const Vec3 n = X_WS.q.Rotate(prim.n[i]);
    list->xyz.insert(list->xyz.end(),
                     {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
    list->normal.insert(list->normal.end(), {static_cast<float>(n.x), static_cast<float>(n.y),
                                             static_cast<float>(n.z)});
    if (own_colors) {
      const Vec3& c = prim.c[i];
      list->rgb.insert(list->rgb.end(), {Byte(c.x), Byte(c.y), Byte(c.z)});
    } else {
      list->rgb.insert(list->rgb.end(), rgb, rgb + 3);
    }
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const Vec3 c = (lo + hi) * 0.5;
  item.center[0] = static_cast<float>(c.x);
  item.center[1] = static_cast<float>(c.y);
  item.center[2] = static_cast<float>(c.z);
  item.radius = static_cast<float>((hi - lo).Norm() * 0.5) + 1e-4f;
  if (item.count > 0) list->items.push_back(item);
  if (item.count > 0 && !emissive) {
    if (!list->has_bounds) {
      list->has_bounds = true;
      list->lo = lo;
      list->hi = hi;
    } else {
      list->lo = {std::min(list->lo.x, lo.x), std::min(list->lo.y, lo.y),
                  std::min(list->lo.z, lo.z)};
      list->hi = {std::max(list->hi.x, hi.x), std::max(list->hi.y, hi.y),
                  std::max(list->hi.z, hi.z)};
    }
  }
}

// Calls f(slot, visual) for every live object whose type declares a visual
// (framework/visual.h), types in ObjectType order, each type's rows in order.
template <typename F>
void ForEachVisual(const Scene& scene, F&& f) {
  const auto types = scene.types();
  for (size_t k = 0; k < types.size(); ++k) {
    const auto hook = types[k]->visual;
    const ObjectType type = static_cast<ObjectType>(k);
    const RowTable* rows = scene.rows(type);
    if (hook == nullptr || rows == nullptr) continue;
    for (uint32_t r = 0; r < rows->size(); ++r) {
      const uint32_t slot = rows->owners[r];
      if (!scene.alive_at(slot)) continue;
      ObjectVisual v;
      hook(scene, type, r, &v);
      f(slot, v);
    }
  }
}

bool IsBlack(const Vec3& c) { return !(c.x > 0 || c.y > 0 || c.z > 0); }

}  // namespace

void BuildDrawList(const World& world, int segments, DrawList* list, double min_led_radius,
                   bool rays) {
  const Scene& scene = world.scene();
  list->xyz.clear();
  list->normal.clear();
  list->rgb.clear();
  list->items.clear();
  list->lights.clear();
  list->ray_xyz.clear();
  list->ray_rgb.clear();
  list->lo = list->hi = Vec3{};
  list->has_bounds = false;
  const Primitives& prims = PrimitivesFor(segments);
  // Solids, as their types declare them (shapes' geometry), in row order.
  ForEachVisual(scene, [&](uint32_t slot, const ObjectVisual& v) {
    const Pose& X = scene.world_pose_at(slot);
    const Vec3& size = v.size;
    switch (v.kind) {
      case VisualKind::kBox: Append(list, slot, prims.box, size, X, v.color, false); break;
      case VisualKind::kCylinder:
        Append(list, slot, prims.cylinder, {size.x, size.x, size.z}, X, v.color, false);
        break;
      case VisualKind::kSphere:
        Append(list, slot, prims.sphere, {size.x, size.x, size.x}, X, v.color, false);
        break;
      case VisualKind::kCapsule:
        Append(list, slot, Capsule(segments, size.x, size.z), {size.x, size.x, size.x}, X, v.color,
               false);
        break;
      case VisualKind::kMesh:
        if (v.mesh != nullptr) {
          const Primitive& mesh = MeshFor(v.mesh);
          Append(list, slot, mesh, {1, 1, 1}, X, v.color, false, v.mesh_colors && !mesh.c.empty());
        }
        break;
      default: break;  // lights below; rays are markers, not drawn here
    }
  });
  // The environment map's boxes.
  if (const EnvironmentMap* env = scene.environment()) {
    const Vec3 color{0.55, 0.5, 0.45};
    for (const EnvironmentBox& b : env->boxes)
      Append(list, kNoSlot, prims.box, b.hi - b.lo, Pose{(b.lo + b.hi) * 0.5, Quat{}}, color,
             false);
  }
  // Lights (LEDs): spheres in their colour, unlit (emissive) while on and
  // not black, dark otherwise.
  ForEachVisual(scene, [&](uint32_t slot, const ObjectVisual& v) {
    if (v.kind != VisualKind::kLight) return;
    const bool lit = v.on && !IsBlack(v.color);
    const double radius = std::max(v.size.x, min_led_radius);
    Append(list, slot, prims.sphere, {radius, radius, radius}, scene.world_pose_at(slot),
           lit ? v.color : Vec3{0.15, 0.15, 0.15}, /*emissive=*/lit);
  });
  // Rays (markers, asked for): a segment along +z, to the hit or full length.
  if (rays)
    ForEachVisual(scene, [&](uint32_t slot, const ObjectVisual& v) {
      if (v.kind != VisualKind::kRay) return;
      const Pose& X = scene.world_pose_at(slot);
      const double length = v.hit >= 0 ? std::min(v.hit, v.size.x) : v.size.x;
      const Vec3 a = X.p, b = X.p + X.q.Rotate(Vec3{0, 0, 1}) * length;
      list->ray_xyz.insert(list->ray_xyz.end(), {static_cast<float>(a.x), static_cast<float>(a.y),
                                                 static_cast<float>(a.z), static_cast<float>(b.x),
                                                 static_cast<float>(b.y), static_cast<float>(b.z)});
      const uint8_t r = Byte(v.color.x), g = Byte(v.color.y), bl = Byte(v.color.z);
      list->ray_rgb.insert(list->ray_rgb.end(), {r, g, bl, r, g, bl});
    });
  // Lights.
  CollectLights(scene, &list->lights, &list->scene_has_lights);
  list->step = world.step_count();
  // The paint layer, laid on the floor.
  list->floor = {};
  if (const ::swarmsim::FloorLayer* layer = world.floor_layer()) {
    const FloorArea area = layer->floor_area();
    list->floor = {true,       area.min_x, area.min_y,  area.max_x,
                   area.max_y, area.width, area.height, layer->floor_rgb().data()};
  }
}

}  // namespace swarmsim::rendering
