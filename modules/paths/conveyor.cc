// The `conveyor` object type (rows.h ConveyorRow): a belt along a curve.
// Its belt is made of box segments, children of the conveyor made when the
// world starts (BuildBelt), each with its x axis along its chord, its top
// face on the curve and a surface velocity (ShapeData::surface_velocity) of
// `speed` along x: the dynamics backends make contacts with it carry what
// lies on it. Segments are scene shapes, so sensors, cameras and recordings
// see the belt, and a model's copies and scaling take it along.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/paths/rows.h"
#include "modules/paths/types.h"

namespace swarmsim::paths {

namespace {

constexpr NumberRule kSpeed{"a finite number of m/s", -kMaxLength, kMaxLength};

constexpr ObjectKey kConveyorKeys[] = {
    {"points", "required",
     "[[x, y, z], ...]: the belt's top centre line, m in the conveyor's frame; at least 2, no two "
     "consecutive ones equal"},
    {"interpolation", "linear",
     "`linear` (straight segments) or `smooth` (a Catmull-Rom spline through the points)"},
    {"closed", "false", "true: the last point joins the first (a loop of belt)"},
    {"width", "0.3", "m, across the belt"},
    {"thickness", "0.05", "m, the belt's depth below its top"},
    {"speed", "0",
     "m/s: how fast the belt's surface moves along the points (negative: backwards); "
     "sim.setConveyorSpeed changes it"},
    {"segment_length", "0.1",
     "m: the longest belt segment along a smooth curve (the belt is made of straight box "
     "segments, children named belt0, belt1, ...)"},
    {"friction", "0.7", "the belt's Coulomb coefficient, >= 0"},
    {"color", "[0.2, 0.2, 0.22]", "RGB, each 0..1"},
};

void ReadConveyor(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  ConveyorRow& c = *static_cast<ConveyorRow*>(row);
  c.curve = ReadCurve(r);
  if (r.Has("width")) c.width = r.Number("width", kPositiveLength);
  if (r.Has("thickness")) c.thickness = r.Number("thickness", kPositiveLength);
  if (r.Has("segment_length")) c.segment_length = r.Number("segment_length", kPositiveLength);
  if (r.Has("speed")) c.speed = r.Number("speed", kSpeed);
  if (r.Has("friction")) c.friction = r.Number("friction", kNonNegative);
  if (r.Has("color")) c.color = r.Vector3("color", kFraction);
}

// Lengths and speeds x s.
void ScaleConveyor(const ObjectTypeDescriptor&, void* row, double s, ScaleContext* context) {
  ConveyorRow& c = *static_cast<ConveyorRow*>(row);
  c.curve = ScaledCurve(c.curve, s, context);
  c.width *= s;
  c.thickness *= s;
  c.segment_length *= s;
  c.speed *= s;
  if (!std::isnan(c.requested_speed)) c.requested_speed *= s;
  if (!std::isnan(c.applied_speed)) c.applied_speed *= s;  // the segments' shapes scale too
  if (c.curvature) {
    std::shared_ptr<const void>& scaled = context->assets[c.curvature.get()];
    if (scaled == nullptr) {
      auto curvature = std::make_shared<std::vector<double>>(*c.curvature);
      for (double& k : *curvature) k /= s;
      scaled = std::move(curvature);
    }
    c.curvature = std::static_pointer_cast<const std::vector<double>>(scaled);
  }
}

void HashConveyors(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<ConveyorRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].speed);
  }
}

// The arc lengths where the belt's segments meet: the control points, and
// smooth segments cut into pieces no longer than segment_length.
std::vector<double> Breaks(const PathCurve& curve, double segment_length) {
  const size_t n = curve.closed() ? curve.points().size() : curve.points().size() - 1;
  std::vector<double> breaks;
  for (size_t i = 0; i < n; ++i) {
    const double a = curve.LengthAtPoint(i), b = curve.LengthAtPoint(i + 1);
    const double parts = curve.interpolation() == Interpolation::kLinear
                             ? 1.0
                             : std::max(1.0, std::ceil((b - a) / segment_length - 1e-9));
    for (int k = 0; k < static_cast<int>(parts); ++k) breaks.push_back(a + (b - a) * k / parts);
  }
  breaks.push_back(curve.length());
  return breaks;
}

}  // namespace

void BuildBelt(Scene* scene, uint32_t slot, ConveyorRow* row) {
  const PathCurve& curve = *row->curve;
  const std::vector<double> breaks = Breaks(curve, row->segment_length);
  const size_t n = breaks.size() - 1;
  std::vector<Vec3> p(n + 1), d(n);
  for (size_t k = 0; k <= n; ++k) p[k] = curve.PoseAt(breaks[k]).p;
  if (curve.closed()) p[n] = p[0];
  for (size_t k = 0; k < n; ++k) d[k] = (p[k + 1] - p[k]).Normalized();
  // Each segment reaches past its ends by half the width times the tangent
  // of half the turn there, so the outer edge of a bend has no gap.
  std::vector<double> extension(n + 1, 0.0);
  for (size_t k = 0; k <= n; ++k) {
    const bool inner = k > 0 && k < n;
    if (!inner && !curve.closed()) continue;
    const Vec3& before = d[k > 0 ? k - 1 : n - 1];
    const Vec3& after = d[k < n ? k : 0];
    const double turn = std::acos(std::clamp(before.Dot(after), -1.0, 1.0));
    extension[k] = row->width / 2 * std::tan(std::min(turn, 1.0) / 2);
  }
  ShapeData belt;
  belt.kind = ShapeKind::kBox;
  belt.friction = row->friction;
  belt.color = row->color;
  belt.mesh_colors = false;
  const ObjectId conveyor = scene->IdAt(slot);
  // Each segment's curvature on a smooth curve: the (signed) turns at its
  // ends, half each, over its length, so that a bend's segments (short
  // against its radius) turn what they carry about the bend's centre. A
  // linear belt's corners are sharp: its straight segments do not turn.
  auto curvature = std::make_shared<std::vector<double>>(n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    // x along the chord, z as near the curve's up as x allows.
    const Vec3 x = d[k];
    const Vec3 up = curve.PoseAt((breaks[k] + breaks[k + 1]) / 2).q.Rotate({0, 0, 1});
    Vec3 z = up - x * x.Dot(up);
    if (z.SquaredNorm() < 1e-12) z = Vec3{0, 0, 1} - x * x.z;
    z = z.Normalized();
    const Vec3 y = z.Cross(x);
    const double chord = (p[k + 1] - p[k]).Norm();
    belt.size = {chord + extension[k] + extension[k + 1], row->width, row->thickness};
    const Vec3 centre = (p[k] + p[k + 1]) * 0.5 + x * ((extension[k + 1] - extension[k]) / 2) -
                        z * (row->thickness / 2);
    scene->AddShape(BeltSegmentName(static_cast<uint32_t>(k)), conveyor,
                    {centre, FromAxes(x, y, z)}, belt);
    // Signed about z: the turn from the segment before to this one, and
    // from this one to the next.
    auto signed_turn = [&](const Vec3& from, const Vec3& to) {
      return std::atan2(from.Cross(to).Dot(z), from.Dot(to));
    };
    double total = 0;
    if (k > 0 || curve.closed()) total += signed_turn(d[k > 0 ? k - 1 : n - 1], x) / 2;
    if (k + 1 < n || curve.closed()) total += signed_turn(x, d[k + 1 < n ? k + 1 : 0]) / 2;
    if (curve.interpolation() == Interpolation::kSmooth && chord > 0)
      (*curvature)[k] = total / chord;
  }
  row->curvature = std::move(curvature);
  row->segments = static_cast<uint32_t>(n);
}

std::shared_ptr<const ObjectTypeDescriptor> ConveyorType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = kConveyorTypeName;
  t->description = "a conveyor: a belt along a curve whose moving surface carries what lies on it";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<ConveyorRow>>();
  };
  t->scale_row = ScaleConveyor;
  t->hash_rows = HashConveyors;
  t->keys = kConveyorKeys;
  t->read = ReadConveyor;
  t->register_lua = RegisterConveyorApi;
  return t;
}

}  // namespace swarmsim::paths
