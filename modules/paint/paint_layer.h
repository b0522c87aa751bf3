// The floor paint layer (the paper's paint nozzle; pheromone-like trails for
// swarms): a raster of the floor that every enabled paint nozzle marks in
// the record phase, written to the run's output folder as paint.png.
//
// Each step, each robot's nozzles stamp into that robot's own stroke buffer
// (robots in parallel); the buffers are then applied in robot order, then
// the scene's nozzles, so where strokes overlap the highest robot's colour
// wins whatever the thread count. A nozzle paints the pixels whose centres
// lie within its radius of its (x, y), when it is above the floor (z >= 0);
// parts of the disc outside the area are dropped.
//
// With a floor (the world's floor layer when the paint layer is made: the
// `floor:` section, modules/floor), the layer starts from it: each pixel
// takes the floor's colour at its centre, and the paint layer becomes the
// world's floor layer in its place, so paint is drawn over the floor and
// ground sensors, snapshots and the viewer see both.
//
// Image: row 0 is the area's +y edge (north up), column 0 its -x edge; pixel
// (c, r) covers x in min_x + [c, c + 1) res and y in max_y - [r + 1, r) res.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "framework/floor_layer.h"
#include "framework/math.h"
#include "framework/module.h"
#include "framework/world.h"
#include "modules/paint/paint_nozzle.h"

namespace swarmsim::paint {

struct PaintSettings {
  double resolution = 0.01;       // m, side of one pixel
  double min_x = -1, min_y = -1;  // m, the floor area covered
  double max_x = 1, max_y = 1;
  Vec3 background{1, 1, 1};  // RGB in [0, 1], unpainted floor
};

// The paint layer as a module: "paint", record phase, order 200 (after the
// swarm metrics); World::AddModule("paint", &settings) makes one.
ModuleDescriptor PaintModule();

// It is the world's floor layer (World::floor_layer): the recorder and the
// renderer read its image through that interface.
class PaintLayer final : public Observer, public FloorLayer {
 public:
  // Throws swarmsim::Error for a bad resolution or area, or an image over
  // 100 megapixels. Starts from `world`'s floor layer if it has one, and
  // becomes its floor layer.
  PaintLayer(World* world, const PaintSettings& settings);
  ~PaintLayer() override;

  FloorArea floor_area() const override;
  std::span<const uint8_t> floor_rgb() const override { return rgb_; }
  // Painted, or drawn on the floor it started from.
  bool floor_marked(int column, int row) const override {
    return painted(column, row) ||
           (!floor_marked_.empty() && floor_marked_[row * width_ + column] != 0);
  }

  void Record(const World& world, std::vector<MetricSample>* out) override;
  // Snapshots (framework/world_state.h): the painted pixels and their
  // colours, as runs; LoadState returns the other pixels to the floor (or
  // the background) they started from.
  bool SaveState(const World& world, StateWriter* out) const override;
  void LoadState(StateReader* in, World* world) override;
  // Writes paint.png into `dir`.
  void WriteOutputs(const std::filesystem::path& dir) const override;
  void ListOutputs(std::vector<OutputFile>* out) const override;

  const PaintSettings& settings() const { return settings_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<uint8_t>& rgb() const { return rgb_; }  // (height x width x 3)
  bool painted(int column, int row) const { return painted_[row * width_ + column] != 0; }
  int64_t painted_count() const;
  // Pixel centre in the world frame (z = 0).
  Vec3 PixelCentre(int column, int row) const;

 private:
  struct Stroke {  // 8 bytes
    uint32_t pixel;
    uint8_t r, g, b;
  };
  void RefreshNozzles(const Scene& scene);
  const Rows<PaintNozzleData>& Nozzles(const Scene& scene) const;
  void Stamp(const Scene& scene, uint32_t slot, std::vector<Stroke>* out) const;
  void Apply(std::vector<Stroke>* strokes);
  // The colour pixel p started with: the floor's under its centre, or the background.
  void StartColor(size_t p, uint8_t out[3]) const;

  World* world_;
  PaintSettings settings_;
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> rgb_;                        // (height x width x 3)
  std::vector<uint8_t> painted_;                    // (height x width)
  std::vector<uint8_t> floor_marked_;               // (height x width), empty without a floor
  const FloorLayer* floor_ = nullptr;               // the floor it started from, if any
  const Rows<PaintNozzleData>* nozzles_ = nullptr;  // the scene's, since the last Record
  uint64_t nozzles_version_ = ~uint64_t{0};
  std::vector<std::vector<uint32_t>> robot_nozzles_;  // nozzle slots per robot (robots)
  std::vector<uint32_t> scene_nozzles_;               // slots of nozzles outside robots
  std::vector<std::vector<Stroke>> strokes_;          // per robot, this step (robots)
  std::vector<Stroke> scene_strokes_;
};

}  // namespace swarmsim::paint
