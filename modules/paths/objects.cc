// The `path` object type (rows.h) and the module's registration.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/paths/module.h"
#include "modules/paths/paths.h"
#include "modules/paths/rows.h"
#include "modules/paths/types.h"

namespace swarmsim::paths {

std::shared_ptr<const PathCurve> ReadCurve(const ObjectReader& r) {
  std::vector<Vec3> points = r.Vector3List("points", 2, kCoordinate, /*required=*/true);
  const bool closed = r.Has("closed") && r.Bool("closed");
  for (size_t i = 1; i < points.size(); ++i)
    if (points[i] == points[i - 1])
      r.FailAtElement("points", i,
                      "points[" + std::to_string(i) + "] repeats points[" + std::to_string(i - 1) +
                          "]: a path segment must have a length");
  if (closed && points.back() == points.front())
    r.FailAtElement("points", points.size() - 1,
                    "the last point repeats the first: a closed path already joins them (drop "
                    "the last point)");
  Interpolation interpolation = Interpolation::kLinear;
  if (r.Has("interpolation") &&
      r.Choice("interpolation", {"linear", "smooth"}) == std::string("smooth"))
    interpolation = Interpolation::kSmooth;
  // Orientations: a yaw per point, or roll, pitch, yaw per point.
  std::vector<Quat> orientations;
  if (r.Has("yaw_deg") && r.Has("orientations_deg"))
    r.FailAtKey("orientations_deg", "give 'yaw_deg' or 'orientations_deg', not both");
  if (r.Has("yaw_deg")) {
    const std::vector<double> yaw = r.Numbers("yaw_deg", points.size(), points.size(), kAngleDeg);
    for (const double a : yaw) orientations.push_back(Quat::FromYaw(a * M_PI / 180));
  } else if (r.Has("orientations_deg")) {
    const std::vector<Vec3> rpy = r.Vector3List("orientations_deg", points.size(), kAngleDeg);
    if (rpy.size() != points.size())
      r.Fail("orientations_deg", "needs one [roll, pitch, yaw] per point (" +
                                     std::to_string(points.size()) + "), got " +
                                     std::to_string(rpy.size()));
    for (const Vec3& a : rpy)
      orientations.push_back(
          Quat::FromRollPitchYaw(a.x * M_PI / 180, a.y * M_PI / 180, a.z * M_PI / 180));
  }
  return std::make_shared<const PathCurve>(std::move(points), interpolation, closed,
                                           std::move(orientations));
}

std::shared_ptr<const PathCurve> ScaledCurve(const std::shared_ptr<const PathCurve>& curve,
                                             double s, ScaleContext* context) {
  std::shared_ptr<const void>& scaled = context->assets[curve.get()];
  if (scaled == nullptr) {
    std::vector<Vec3> points = curve->points();
    for (Vec3& point : points) point = point * s;
    scaled = std::make_shared<const PathCurve>(std::move(points), curve->interpolation(),
                                               curve->closed(), curve->orientations());
  }
  return std::static_pointer_cast<const PathCurve>(scaled);
}

namespace {

constexpr ObjectKey kPathKeys[] = {
    {"points", "required",
     "[[x, y, z], ...]: control points, m in the path's frame; at least 2, no two consecutive "
     "ones equal"},
    {"interpolation", "linear",
     "`linear` (straight segments) or `smooth` (a Catmull-Rom spline through the points)"},
    {"closed", "false", "true: the last point joins the first, and followers wrap around"},
    {"velocity", "0", "m/s: how fast the followers move along the path (negative: backwards)"},
    {"start", "0", "m: the followers' starting arc length along the path"},
    {"yaw_deg", "none",
     "[a0, a1, ...]: one heading per point, degrees about the path's z; followers turn from "
     "each point's to the next one's (slerp) instead of following the tangent"},
    {"orientations_deg", "none",
     "[[roll, pitch, yaw], ...]: one full orientation per point, degrees (as `orientation_deg`), "
     "slerped between points instead of following the tangent"},
    {"pauses", "none",
     "[s0, s1, ...]: seconds the followers stop at each point (one per point, >= 0), on the "
     "way there in either direction"},
    {"followers", "none",
     "[name, ...]: children of the path that ride it, each keeping its own pose as an offset in "
     "the frame moving along the path (x along the tangent)"},
};

void ReadPath(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  PathRow& p = *static_cast<PathRow*>(row);
  p.curve = ReadCurve(r);
  if (r.Has("velocity")) p.velocity = r.Number("velocity", kCoordinate);
  if (r.Has("start")) p.position = p.curve->Normalize(r.Number("start", kCoordinate));
  if (r.Has("pauses")) {
    const size_t n = p.curve->points().size();
    p.pauses = r.Numbers("pauses", n, n, kNonNegative);
  }
  if (r.Has("followers")) {
    p.where = r.Where("followers");
    p.followers = r.Strings("followers", 1000);
  }
}

// Lengths x s: the points (one scaled curve per call, shared by the copies
// it scales), the position and speed along it, the followers' offsets.
void ScalePath(const ObjectTypeDescriptor&, void* row, double s, ScaleContext* context) {
  PathRow& p = *static_cast<PathRow*>(row);
  p.curve = ScaledCurve(p.curve, s, context);
  p.position *= s;
  p.velocity *= s;
  for (Pose& offset : p.offsets) offset.p = offset.p * s;
}

void HashPaths(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<PathRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const PathRow& p = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(p.position);
    h->AddValue(p.velocity);
    if (!p.pauses.empty()) h->AddValue(p.pause_left);
  }
}

// Each follower is a child of the path.
void CheckPath(const Scene& scene, ObjectId id, const void* row) {
  const PathRow& p = *static_cast<const PathRow*>(row);
  for (const std::string& name : p.followers)
    if (FindFollower(scene, scene.SlotOf(id), name) == kNoSlot)
      throw Error((p.where.empty() ? "" : p.where + ": ") + "path " + scene.PathOf(id) +
                  ": follower '" + name + "' is not a child of the path");
}

std::shared_ptr<const ObjectTypeDescriptor> PathType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = kTypeName;
  t->description = "a path: control points joined straight or smoothly, which children can follow";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<PathRow>>();
  };
  t->scale_row = ScalePath;
  t->hash_rows = HashPaths;
  t->keys = kPathKeys;
  t->read = ReadPath;
  t->check = CheckPath;
  t->register_lua = RegisterPathApi;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"calculation", kModuleName, "1.0",
        "path objects and their followers, moved along them in the actuate phase (path type)"},
       PhaseBit(Phase::kActuate),
       50,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<PathsModule>(); }});
  registry->RegisterObjectType(PathType());
  registry->RegisterObjectType(ConveyorType());
}

}  // namespace swarmsim::paths
