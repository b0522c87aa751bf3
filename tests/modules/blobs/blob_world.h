// What the blob cameras' tests build on: robots with LEDs and cameras in a
// World built in code (kinematic physics), and the readings of a camera.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"

namespace swarmsim::blobs_test {

inline const Vec3 kRed{1, 0, 0}, kGreen{0, 1, 0}, kBlue{0, 0, 1};

inline ShapeData Cylinder(double radius, double height) {
  ShapeData s;
  s.kind = ShapeKind::kCylinder;
  s.size = {radius, 0, height};
  return s;
}

inline ShapeData Box(const Vec3& size) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  return s;
}

// A world of robots built in code (kinematic physics: nothing moves).
class BlobWorld {
 public:
  explicit BlobWorld(int threads = 1) {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = "kinematic";
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    Scene& s = scene();
    EXPECT_TRUE(s.FindType(kLedTypeName, &led_type_));
    EXPECT_TRUE(s.FindType(kBlobCameraTypeName, &camera_type_));
  }
  Scene& scene() { return world_->scene(); }
  World& world() { return *world_; }

  // A robot: a cylinder body (r 0.085 m, 0.146 m high, centre 0.073 m up)
  // at (x, y) facing `yaw`; `body` false gives a bare dummy root.
  ObjectId Robot(double x, double y, double yaw = 0, bool body = true) {
    const std::string name = "bot#" + std::to_string(scene().instances().size());
    const Pose X_WR{{x, y, 0.073}, Quat::FromYaw(yaw)};
    const ObjectId root = body ? scene().AddShape(name, {}, X_WR, Cylinder(0.085, 0.146))
                               : scene().AddDummy(name, {}, X_WR);
    scene().MakeModelInstance(root, "bot", name);
    return root;
  }
  ObjectId Led(ObjectId parent, const Vec3& p, const Vec3& color, bool on = true) {
    LedRow row;
    row.color = color;
    row.on = on;
    return scene().AddObject(led_type_, "led", parent, {p, {}}, &row);
  }
  ObjectId Camera(ObjectId parent, const Pose& X_PC, const BlobCameraRow& row = {}) {
    return scene().AddObject(camera_type_, "camera", parent, X_PC, &row);
  }
  // A robot at (x, y) with an LED of `color` on top (0.156 m above the ground).
  ObjectId LedRobot(double x, double y, const Vec3& color) {
    const ObjectId root = Robot(x, y);
    Led(root, {0, 0, 0.083}, color);
    return root;
  }
  // A robot at (x, y) facing `yaw` with a camera 0.2 m above the ground.
  ObjectId CameraRobot(double x, double y, double yaw, const BlobCameraRow& row = {}) {
    const ObjectId root = Robot(x, y, yaw);
    return Camera(root, {{0, 0, 0.127}, {}}, row);
  }
  // The camera's blobs after one step.
  std::vector<Blob> See(ObjectId camera) {
    world_->Step();
    return Blobs(camera);
  }
  const std::vector<Blob>& Blobs(ObjectId camera) {
    auto& rows = static_cast<Rows<BlobCameraRow>&>(*scene().rows(camera_type_));
    return rows.rows[scene().row_at(scene().SlotOf(camera))].blobs;
  }
  ObjectType led_type() const { return led_type_; }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  ObjectType led_type_{}, camera_type_{};
};

}  // namespace swarmsim::blobs_test
