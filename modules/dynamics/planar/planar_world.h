// The planar backend's world (see planar_backend.h for the model): bodies in
// dense arrays, wheels as precomputed columns of the rolling solve, static
// obstacles in a fixed grid, candidate pairs in Verlet lists. Internal to
// this folder.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/math.h"
#include "framework/spatial_grid.h"
#include "modules/dynamics/height_range.h"
#include "modules/dynamics/obstacle_poses.h"
#include "modules/dynamics/planar/planar_contact.h"
#include "modules/dynamics/planar/planar_options.h"

namespace swarmsim {
class Scene;
class StateHasher;
struct ShapeData;
}  // namespace swarmsim

namespace swarmsim::planar {

// A wheel: how its surface speed moves its body (a column of the body's
// least-squares rolling solve, body plane frame).
struct PlanarWheel {  // 40 bytes
  uint32_t joint_slot = 0;
  double radius = 0;          // m
  double g_vx = 0, g_vy = 0;  // body velocity per unit surface speed
  double g_w = 0;             // rad per m of surface travel
};

// What the scene does not hold about a body.
struct PlanarBodyCold {  // 144 bytes
  uint32_t slot = 0;
  uint32_t first_wheel = 0, wheel_count = 0;
  double yaw = 0;       // rad, unwrapped
  double z = 0;         // m, kept
  Quat q_tilt;          // roll and pitch, kept
  Pose X_WB_last;       // pose last written to (or read from) the scene
  double yaw_last = 0;  // yaw of X_WB_last
};

class PlanarWorld {
 public:
  PlanarWorld(const Options& options, const DynamicsSettings& settings);

  // Bodies, obstacles and wheels from the scene (discarding any previous).
  void Build(const Scene& scene);
  // Moves bodies whose scene pose was set from outside since the last write,
  // and the obstacles when a static shape behind one moved.
  void SyncFromScene(const Scene& scene);
  // Each body's velocity from its wheels' commands (and Push's, which the
  // body then moves by exactly over `duration` s when nothing stops it).
  void ReadCommands(const Scene& scene, double duration = 0);
  // Velocities set from outside (World::SetVelocities) for the shapes at
  // `slots`: each of them that is a body moves at its scene velocity (world
  // frame, taken now) on top of its wheels' for the next Advance only (no
  // inertia here); EndPushes, after that Advance, forgets them.
  void Push(const Scene& scene, std::span<const uint32_t> slots);
  void EndPushes();
  // Moves every body by its wheels for `duration` seconds and resolves the
  // overlaps, in internal steps small enough that nothing tunnels.
  void Advance(double duration);
  // Poses and velocities (what moved / duration).
  void WriteBack(Scene* scene, double duration);
  void Hash(StateHasher* hasher) const;

  int body_count() const { return static_cast<int>(shapes_.size()); }
  // Internal steps the last Advance took.
  int last_internal_steps() const { return last_internal_steps_; }

 private:
  void AddObstacle(const ShapeData& shape, const Pose& X_WS);
  // The static shapes of obstacle_poses_ that reach into dynamic_range_, as
  // obstacles (appended), where they are now.
  void PlaceShapeObstacles(const Scene& scene);
  // The obstacles' grid; the neighbour lists are built again.
  void IndexObstacles();
  void RebuildPairs();
  // Parallel over bodies (inline without a scheduler).
  template <class F>
  void ForBodies(F&& body);

  // A velocity set from outside for one step (Push).
  struct PushedBody {  // 32 bytes
    uint32_t body;
    double vx, vy, w;  // world frame (m/s, rad/s)
  };

  Options options_;
  DynamicsSettings settings_;
  // Bodies, slot order.
  std::vector<PlaneShape> shapes_;                     // current iterate (bodies)
  std::vector<PlaneShape> next_;                       // Jacobi scratch (bodies)
  std::vector<double> bound_;                          // bounding radius, m (bodies)
  std::vector<double> inner_;                          // inner radius, m (bodies)
  std::vector<double> inverse_mass_;                   // 1/kg (bodies)
  std::vector<double> v_x_, v_y_, w_;                  // commanded velocity, body frame (bodies)
  std::vector<PushedBody> pushes_;                     // Push, until EndPushes (body order)
  std::vector<double> start_x_, start_y_, start_yaw_;  // at the start of Advance (bodies)
  std::vector<PlanarBodyCold> cold_;                   // (bodies)
  std::vector<PlanarWheel> wheels_;                    // grouped by body
  std::vector<uint32_t> wheeled_;                      // bodies with wheels, ascending
  // Static obstacles and their grid: the static shapes' (the first
  // shape_obstacles_, placed again when one of them moved: SyncFromScene),
  // then the environment map's voxels'.
  std::vector<PlaneShape> obstacles_;
  size_t shape_obstacles_ = 0;
  SpatialGrid obstacle_grid_;
  dynamics::ObstaclePoses obstacle_poses_;     // the shapes that may be obstacles
  dynamics::HeightRange dynamic_range_{0, 0};  // of the bodies, at Build
  // Verlet lists: candidates within bound + skin at the last rebuild.
  double skin_ = 0;                                    // m
  std::vector<double> ref_x_, ref_y_;                  // positions at the last rebuild (bodies)
  std::vector<std::vector<uint32_t>> near_;            // bodies (bodies)
  std::vector<std::vector<uint32_t>> near_obstacles_;  // obstacles (bodies)
  bool pairs_valid_ = false;
  SpatialGrid body_grid_;
  std::vector<GridItem> items_;  // scratch
  double max_speed_ratio_ = 0;   // max over bodies of speed / (fraction * inner radius), 1/s
  int last_internal_steps_ = 0;
};

}  // namespace swarmsim::planar
