// Blob cameras: which lit LEDs each camera sees.
//
// Each sense phase:
// 1. the lit LEDs (on and not black) go into a 2D grid over their (x, y);
// 2. if any camera tests occlusion, every shape is placed at its pose and
//    goes into a second grid, its (x, y) bounds as a circle (walls, larger
//    than a cell, go to the grid's short list every query scans); the
//    environment map's voxels are the world's line of sight (the proximity
//    backend's, frozen when the world starts; SegmentBlocked);
// 3. every camera, in parallel (each writes only its own row): the LEDs of
//    the grid cells within its range, minus its own robot's, those within
//    range in 3D and inside its field of view; each tested for occlusion
//    by a segment from the camera's origin to the LED's centre: the shapes
//    near the camera that reach the heights of those segments (listed once
//    per camera), each against its bounding box, then the exact ray test
//    of modules/proximity/ray_cast.h; then the map's voxels.
//    The shapes of the camera's robot and of the LED's robot never hide it
//    (ARGoS's rule: a robot's LEDs are seen through its own body); for a
//    camera or LED of no robot, the shapes it hangs from.
// Noise, if the camera has any, is drawn per camera and step from a stream
// keyed by (seed, camera slot, step), blob by blob in LED row order. A
// camera's blobs are then sorted by bearing, distance, then handle: the
// reading does not depend on the grid, the thread count or row order.
#include "modules/blobs/module.h"

#include <algorithm>
#include <cmath>

#include "framework/line_of_sight.h"
#include "framework/random.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/sensor_noise.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"

namespace swarmsim::blobs {

namespace {

constexpr double kTwoPi = 6.283185307179586;
constexpr double kPi = 3.141592653589793;
// The occlusion segment stops this short of the LED (m), so that the shape
// an LED sits on the surface of does not hide it.
constexpr double kEndMargin = 1e-6;
// Cameras per task: a camera costs about a microsecond.
constexpr int64_t kCameraGrain = 16;

bool BlobBefore(const Blob& a, const Blob& b) {
  if (a.bearing != b.bearing) return a.bearing < b.bearing;
  if (a.distance != b.distance) return a.distance < b.distance;
  return a.led < b.led;
}

}  // namespace

void BlobCameraModule::IndexLeds(const Scene& scene, ObjectType led_type) {
  leds_.clear();
  led_items_.clear();
  const auto& rows = static_cast<const Rows<LedRow>&>(*scene.rows(led_type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const LedRow& led = rows.rows[r];
    if (!led.lit()) continue;
    const uint32_t slot = rows.owners[r];
    const Vec3& p = scene.world_pose_at(slot).p;
    led_items_.push_back({p.x, p.y, 0, static_cast<uint32_t>(leds_.size())});
    leds_.push_back({p, led.color, scene.IdAt(slot), scene.instance_of_at(slot), slot});
  }
  if (!leds_.empty()) led_grid_.Build(led_items_);
}

void BlobCameraModule::IndexOccluders(const Scene& scene, double z_lo, double z_hi) {
  occluders_.clear();
  occluder_items_.clear();
  const auto shapes = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shapes.size(); ++r) {
    const uint32_t slot = owners[r];
    Occluder& o = occluders_.emplace_back();
    o.shape = proximity::PlaceShape(shapes[r], scene.world_pose_at(slot), scene.IdAt(slot),
                                    scene.instance_of_at(slot));
    o.slot = slot;
    proximity::WorldBounds(o.shape, &o.lo, &o.hi);
    // Grown a little: the exact test decides, these only must not miss.
    const double margin = 1e-9 * (1 + std::abs(o.lo.x) + std::abs(o.lo.y) + std::abs(o.lo.z) +
                                  std::abs(o.hi.x) + std::abs(o.hi.y) + std::abs(o.hi.z));
    o.lo = o.lo - Vec3{margin, margin, margin};
    o.hi = o.hi + Vec3{margin, margin, margin};
    if (o.hi.z < z_lo || o.lo.z > z_hi) {
      occluders_.pop_back();
      continue;
    }
    occluder_items_.push_back({0.5 * (o.lo.x + o.hi.x), 0.5 * (o.lo.y + o.hi.y),
                               0.5 * std::hypot(o.hi.x - o.lo.x, o.hi.y - o.lo.y),
                               static_cast<uint32_t>(occluder_items_.size())});
  }
  occluder_grid_.Build(occluder_items_);
}

void BlobCameraModule::ListOccluders(const Scene& scene, const Vec3& p_W, double range,
                                     int instance, uint32_t slot, double z_lo, double z_hi,
                                     std::vector<uint32_t>* out) const {
  occluder_grid_.QueryCircle(p_W.x, p_W.y, range, out);
  size_t kept = 0;
  for (uint32_t j : *out) {
    const Occluder& o = occluders_[j];
    const int owner = o.shape.instance;
    if (owner >= 0 ? owner == instance : scene.IsAbove(o.slot, slot)) continue;
    if (o.hi.z < z_lo || o.lo.z > z_hi) continue;
    (*out)[kept++] = j;
  }
  out->resize(kept);
}

bool BlobCameraModule::Hidden(const Scene& scene, const Vec3& p_W, const LitLed& led,
                              double distance, const std::vector<uint32_t>& occluders) const {
  const double length = distance - kEndMargin;
  if (!(length > 0)) return false;
  const Vec3 d_W = (led.p_W - p_W) / distance;
  const Vec3 end = p_W + d_W * length;
  const proximity::Segment segment(p_W, end - p_W);
  for (uint32_t j : occluders) {
    const Occluder& o = occluders_[j];
    const int owner = o.shape.instance;
    if (owner >= 0 ? owner == led.instance : scene.IsAbove(o.slot, led.slot)) continue;
    if (!segment.MeetsBox(o.lo, o.hi)) continue;
    double hit = 0;
    if (proximity::RayCast(o.shape, p_W, d_W, length, &hit)) return true;
  }
  return map_ != nullptr && map_->SegmentBlocked(p_W, end);
}

void BlobCameraModule::See(const Scene& scene, uint32_t slot, BlobCameraRow* camera) const {
  BlobCameraRow& c = *camera;
  c.blobs.clear();
  if (!c.enabled || leds_.empty()) return;
  const Pose& X_WC = scene.world_pose_at(slot);
  const Vec3& p_W = X_WC.p;
  const Quat q_CW = X_WC.q.Conjugate();
  const int instance = scene.instance_of_at(slot);
  const bool all_around = c.fov >= kTwoPi, all_up_down = c.vertical_fov >= kPi;
  const double half_fov = 0.5 * c.fov, half_vertical = 0.5 * c.vertical_fov;
  const double range2 = c.range * c.range;
  // The LEDs in range and view (seen[k]: the LED of blobs[k]), and the
  // heights their segments from the camera span.
  thread_local std::vector<uint32_t> near, seen, occluders;
  led_grid_.QueryCircle(p_W.x, p_W.y, c.range, &near);
  seen.clear();
  double z_lo = p_W.z, z_hi = p_W.z;
  for (uint32_t i : near) {
    const LitLed& led = leds_[i];
    if (instance >= 0 && led.instance == instance) continue;  // its own robot's
    const Vec3 d_W = led.p_W - p_W;
    const double d2 = d_W.SquaredNorm();
    if (!(d2 <= range2) || d2 == 0) continue;
    const Vec3 d_C = q_CW.Rotate(d_W);
    double bearing = std::atan2(d_C.y, d_C.x);
    if (bearing == -kPi) bearing = kPi;  // (-pi, pi]: straight behind is +pi
    if (!all_around && std::abs(bearing) > half_fov) continue;
    const double elevation = std::atan2(d_C.z, std::hypot(d_C.x, d_C.y));
    if (!all_up_down && std::abs(elevation) > half_vertical) continue;
    c.blobs.push_back({led.color, std::sqrt(d2), bearing, elevation, led.id});
    seen.push_back(i);
    z_lo = std::min(z_lo, led.p_W.z);
    z_hi = std::max(z_hi, led.p_W.z);
  }
  // Occlusion: the shapes near the camera at those heights, but its own,
  // tested for each LED.
  if (c.occlusion && !seen.empty()) {
    ListOccluders(scene, p_W, c.range, instance, slot, z_lo, z_hi, &occluders);
    size_t kept = 0;
    for (size_t k = 0; k < seen.size(); ++k)
      if (!Hidden(scene, p_W, leds_[seen[k]], c.blobs[k].distance, occluders))
        c.blobs[kept++] = c.blobs[k];
    c.blobs.resize(kept);
  }
  // A failing camera sees nothing this step (its own stream: the noise
  // draws below stay what they were without failures).
  if (c.failure > 0 && !c.blobs.empty()) {
    Rng rng = NoiseStream(seed_, slot, static_cast<int64_t>(step_), NoisePurpose::kBlobCamera);
    if (Fails(NoiseSettings{.failure = c.failure}, rng)) c.blobs.clear();
  }
  if (c.angle_noise > 0 || c.distance_noise > 0) AddNoise(slot, &c);
  std::sort(c.blobs.begin(), c.blobs.end(), BlobBefore);
}

void BlobCameraModule::AddNoise(uint32_t slot, BlobCameraRow* camera) const {
  Rng rng(seed_, (uint64_t{slot} << 40) ^ step_);
  for (Blob& b : camera->blobs) {
    if (camera->angle_noise > 0) {
      b.bearing = std::remainder(b.bearing + rng.Normal(0, camera->angle_noise), kTwoPi);
      if (b.bearing == -kPi) b.bearing = kPi;  // (-pi, pi]
      b.elevation =
          std::clamp(b.elevation + rng.Normal(0, camera->angle_noise), -0.5 * kPi, 0.5 * kPi);
    }
    if (camera->distance_noise > 0)
      b.distance = std::max(0.0, b.distance * (1 + rng.Normal(0, camera->distance_noise)));
  }
}

int BlobCameraModule::SetLed(Scene* scene, int robot, ObjectId id, const Vec3& color,
                             bool on) const noexcept {
  // The type the sense phase found, once it looked (no search by name).
  ObjectType type = led_type_;
  if (!(types_found_ ? have_types_ : scene->FindType(kLedTypeName, &type)) || !scene->IsValid(id) ||
      robot < 0 || scene->instance_of(id) != robot)
    return -1;
  const uint32_t slot = scene->SlotOf(id);
  if (scene->type_at(slot) != type) return -1;
  LedRow& led = static_cast<Rows<LedRow>&>(*scene->rows(type)).rows[scene->row_at(slot)];
  // Each channel clamped to 0..1 (NaN reads 0).
  const auto channel = [](double v) { return v > 0 ? (v < 1 ? v : 1.0) : 0.0; };
  led.color = {channel(color.x), channel(color.y), channel(color.z)};
  led.on = on;
  return 0;
}

void BlobCameraModule::Sense(World* world) {
  Scene& scene = world->scene();
  if (!types_found_) {
    have_types_ = scene.FindType(kLedTypeName, &led_type_) &&
                  scene.FindType(kBlobCameraTypeName, &camera_type_);
    types_found_ = true;
  }
  if (!have_types_) return;
  seed_ = world->settings().seed;
  step_ = static_cast<uint64_t>(world->step_count());
  auto& cameras = static_cast<Rows<BlobCameraRow>&>(*scene.rows(camera_type_));
  if (cameras.size() == 0) return;
  const EnvironmentMap* map = scene.environment();
  map_ = map != nullptr && !map->boxes.empty() ? world->line_of_sight() : nullptr;
  IndexLeds(scene, led_type_);
  // The heights every occlusion segment stays within: those of the lit
  // LEDs and of the cameras that test occlusion.
  bool occlusion = false;
  double z_lo = INFINITY, z_hi = -INFINITY;
  for (size_t r = 0; r < cameras.size(); ++r) {
    if (!cameras.rows[r].enabled || !cameras.rows[r].occlusion) continue;
    occlusion = true;
    const double z = scene.world_pose_at(cameras.owners[r]).p.z;
    z_lo = std::min(z_lo, z), z_hi = std::max(z_hi, z);
  }
  for (const LitLed& led : leds_)
    z_lo = std::min(z_lo, led.p_W.z), z_hi = std::max(z_hi, led.p_W.z);
  if (occlusion && !leds_.empty()) IndexOccluders(scene, z_lo, z_hi);
  world->scheduler().ParallelFor(0, static_cast<int64_t>(cameras.size()), kCameraGrain,
                                 [&](int64_t begin, int64_t end) {
                                   for (int64_t r = begin; r < end; ++r)
                                     See(scene, cameras.owners[r], &cameras.rows[r]);
                                 });
}

}  // namespace swarmsim::blobs
