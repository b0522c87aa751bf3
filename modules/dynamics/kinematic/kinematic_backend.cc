#include "modules/dynamics/kinematic/kinematic_backend.h"

#include <cmath>
#include <vector>

#include "framework/scene.h"

namespace swarmsim::kinematic {

namespace {

// Nothing is simulated; but a robot given a velocity from outside
// (World::SetVelocities: Python's World.set_velocities) moves at it for the
// next step: its root along v_W, turning about w_W, then its velocities are
// zero again (no inertia, as everything here). The velocities wait in the
// scene (hashed and saved with it), so a snapshot in between keeps them.
class KinematicBackend final : public DynamicsBackend {
 public:
  void Build(const Scene& scene, const DynamicsSettings& /*settings*/) override { Collect(scene); }
  bool TakeVelocities(Scene* scene, std::span<const uint32_t> /*slots*/) override {
    Collect(*scene);
    return true;
  }
  void Step(Scene* scene, double dt, int substeps) override {
    if (moving_.empty()) return;
    const double duration = dt * substeps;
    for (const int robot : moving_) {
      const ObjectId root = scene->instance(robot).root;
      const uint32_t root_slot = scene->SlotOf(root);
      const Vec3 v = scene->linear_velocity_at(root_slot),
                 w = scene->angular_velocity_at(root_slot);
      Pose X = scene->world_pose_at(root_slot);
      X.p = X.p + v * duration;
      const double turn = std::sqrt(w.Dot(w)) * duration;
      if (turn > 0) X.q = (Quat::FromAxisAngle(w / std::sqrt(w.Dot(w)), turn) * X.q).Normalized();
      scene->SetWorldPose(root, X);
    }
    for (const int robot : moving_)
      for (const uint32_t s : scene->instance(robot).objects) scene->SetVelocityAt(s, {}, {});
    moving_.clear();
  }
  int body_count() const override { return 0; }

 private:
  // The robots whose root has a velocity (only World::SetVelocities gives one here).
  void Collect(const Scene& scene) {
    moving_.clear();
    const Vec3 zero{};
    for (size_t r = 0; r < scene.instances().size(); ++r) {
      const ModelInstance& robot = scene.instances()[r];
      if (!robot.alive) continue;
      const uint32_t slot = scene.SlotOf(robot.root);
      if (scene.linear_velocity_at(slot) == zero && scene.angular_velocity_at(slot) == zero)
        continue;
      moving_.push_back(static_cast<int>(r));
    }
  }
  std::vector<int> moving_;  // robots, ascending
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"dynamics", "kinematic", "1.0",
          "no dynamics: objects move only by scripts, IK and joint targets"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return std::make_unique<KinematicBackend>(); }

}  // namespace swarmsim::kinematic
