// shape: a rigid body's geometry (box, cylinder, sphere, capsule, triangle
// mesh), static, moved with its parent, or simulated by the dynamics backend.
#include <cmath>

#include "framework/mesh.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/types/core_types.h"

namespace swarmsim {
namespace {

constexpr ObjectKey kKeys[] = {
    {"shape", "required",
     "box, cylinder, sphere or capsule, centred on the object's frame (a cylinder's or capsule's "
     "axis is its z), or mesh"},
    {"size", "box: required", "m, [x, y, z] full extents (boxes only)"},
    {"radius", "cylinder, sphere, capsule: required", "m"},
    {"height", "cylinder, capsule: required", "m, along z; a capsule's includes its caps"},
    {"dynamic", "false",
     "simulated by the physics backend; otherwise static or moved with its parent"},
    {"mass", "1", "kg (dynamic shapes)"},
    {"inertia", "from the geometry",
     "[ixx, iyy, izz, ixy, ixz, iyz] kg m^2 about the shape's origin (dynamic shapes, ode)"},
    {"collidable", "true", "false: no contacts in the physics backends (sensors still see it)"},
    {"visible", "true",
     "false: not drawn (viewer, snapshots, video, vision sensors); still collides and proximity "
     "sensors still detect it"},
    {"friction", "0.7", "Coulomb coefficient, >= 0"},
    {"restitution", "0", "0..1"},
    {"color", "[0.7, 0.7, 0.7]", "RGB, each 0..1"},
    {"file", "mesh: required", "STL, OBJ or COLLADA file, relative to the file naming it; metres"},
    {"scale", "mesh: [1, 1, 1]",
     "[sx, sy, sz], positive factors applied to the file's coordinates"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<Shared<ShapeData>>>();
}

// Sizes and surface velocity x s (not its angular velocity), mass x s^3; a mesh gets a scaled copy
// of its asset, one per asset per call (context), so copies duplicated afterwards share it.
void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext* context) {
  ShapeData& shape = static_cast<Shared<ShapeData>*>(row)->Edit();  // this copy's own
  shape.size = shape.size * s;
  shape.mass *= s * s * s;
  shape.center_of_mass = shape.center_of_mass * s;
  for (double& i : shape.inertia) i *= s * s * s * s * s;
  shape.surface_velocity = shape.surface_velocity * s;
  if (!shape.mesh) return;
  std::shared_ptr<const void>& scaled = context->assets[shape.mesh.get()];
  if (!scaled) {
    std::vector<Vec3> vertices(shape.mesh->vertices().begin(), shape.mesh->vertices().end());
    for (Vec3& v : vertices) v = v * s;
    std::vector<MeshTriangle> triangles(shape.mesh->triangles().begin(),
                                        shape.mesh->triangles().end());
    scaled = std::make_shared<const TriangleMesh>(
        shape.mesh->name(), std::move(vertices), std::move(triangles),
        std::vector<Vec3>(shape.mesh->colors().begin(), shape.mesh->colors().end()));
  }
  shape.mesh = std::static_pointer_cast<const TriangleMesh>(scaled);
  shape.size = shape.mesh->CenteredExtents();
}

// Each kind takes its own size keys; a key of another kind is a mistake.
void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  ShapeData& s = static_cast<Shared<ShapeData>*>(row)->Edit();
  const std::string kind =
      r.Choice("shape", {"box", "cylinder", "sphere", "capsule", "mesh"}, /*required=*/true);
  auto forbid = [&](const char* key, const char* hint) {
    if (!r.Has(key)) return;
    std::string message = "'";
    message.append(key).append("' does not apply to a ").append(kind);
    message.append(" (").append(hint).append(")");
    r.FailAtKey(key, message);
  };
  if (kind != "mesh") {
    forbid("file", "only a mesh takes 'file: part.stl'");
    forbid("scale", "only a mesh takes 'scale: [sx, sy, sz]'");
  }
  if (kind == "mesh") {
    s.kind = ShapeKind::kMesh;
    for (const char* key : {"size", "radius", "height"})
      forbid(key, "a mesh takes 'file: part.stl|part.obj' and optionally 'scale: [sx, sy, sz]'");
    const Vec3 scale = r.Has("scale") ? r.Vector3("scale", kPositive) : Vec3{1, 1, 1};
    s.mesh = r.Mesh("file", scale);
    s.size = s.mesh->CenteredExtents();
  } else if (kind == "box") {
    s.kind = ShapeKind::kBox;
    forbid("radius", "a box takes 'size: [x, y, z]'");
    forbid("height", "a box takes 'size: [x, y, z]'");
    s.size = r.Vector3("size", kPositiveLength, /*required=*/true);
  } else if (kind == "cylinder" || kind == "capsule") {
    s.kind = kind == "cylinder" ? ShapeKind::kCylinder : ShapeKind::kCapsule;
    forbid("size", kind == "cylinder" ? "a cylinder takes 'radius' and 'height'"
                                      : "a capsule takes 'radius' and 'height' (caps included)");
    s.size = {r.Number("radius", kPositiveLength, true), 0,
              r.Number("height", kPositiveLength, true)};
    if (kind == "capsule" && s.size.z < 2 * s.size.x)
      r.Fail("height",
             "a capsule's height includes its caps: it must be at least twice its radius");
  } else {
    s.kind = ShapeKind::kSphere;
    forbid("size", "a sphere takes 'radius'");
    forbid("height", "a sphere takes 'radius'");
    s.size = {r.Number("radius", kPositiveLength, true), 0, 0};
  }
  if (r.Has("dynamic")) s.dynamic = r.Bool("dynamic");
  if (r.Has("mass")) s.mass = r.Number("mass", kMass);
  if (r.Has("inertia")) {
    const std::vector<double> i = r.Numbers("inertia", 6, 6, kAnyNumber);
    if (!InertiaIsValid({i[0], i[1], i[2], i[3], i[4], i[5]}))
      r.Fail("inertia",
             "'inertia' [ixx, iyy, izz, ixy, ixz, iyz] must be positive definite, each principal "
             "moment at most the sum of the other two");
    std::copy(i.begin(), i.end(), s.inertia.begin());
  }
  if (r.Has("collidable")) s.collidable = r.Bool("collidable");
  if (r.Has("visible")) s.visible = r.Bool("visible");
  if (r.Has("friction")) s.friction = r.Number("friction", kNonNegative);
  if (r.Has("restitution")) s.restitution = r.Number("restitution", kFraction);
  if (r.Has("color")) {
    s.color = r.Vector3("color", kFraction);
    s.mesh_colors = false;
  }
}

}  // namespace

bool InertiaIsValid(const std::array<double, 6>& i) {
  const double xx = i[0], yy = i[1], zz = i[2], xy = i[3], xz = i[4], yz = i[5];
  for (double v : i)
    if (!std::isfinite(v)) return false;
  // Positive definite (Sylvester's criterion) and the triangle inequality
  // of the principal moments, which ODE checks too (a little slack).
  const double m2 = xx * yy - xy * xy;
  const double m3 = xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
  if (!(xx > 0 && m2 > 0 && m3 > 0)) return false;
  const double slack = 1e-9 * (xx + yy + zz);
  return xx <= yy + zz + slack && yy <= xx + zz + slack && zz <= xx + yy + slack;
}

namespace {

// Drawn as its geometry, in its colour (which scripts may change).
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const ShapeData& s = *scene.rows<Shared<ShapeData>>(type).rows[row];
  if (!s.visible) return;  // kNone: drawn by nothing
  switch (s.kind) {
    case ShapeKind::kBox: out->kind = VisualKind::kBox; break;
    case ShapeKind::kCylinder: out->kind = VisualKind::kCylinder; break;
    case ShapeKind::kSphere: out->kind = VisualKind::kSphere; break;
    case ShapeKind::kCapsule: out->kind = VisualKind::kCapsule; break;
    case ShapeKind::kMesh: out->kind = VisualKind::kMesh; break;
  }
  out->size = s.size;
  out->color = s.color;
  out->mesh = s.mesh.get();
  out->mesh_colors = s.mesh_colors && s.mesh != nullptr && !s.mesh->colors().empty();
}

}  // namespace

constinit const ObjectTypeDescriptor kShapeType{
    .name = "shape",
    .description = "a rigid body's geometry: box, cylinder, sphere, capsule or triangle mesh",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .keys = kKeys,
    .read = Read,
    .visual = Visual,
};

}  // namespace swarmsim
