// The range-and-bearing module (internal to modules/range_and_bearing): in
// the sense phase it indexes every board's position (and, if a board asks,
// the shapes that may block), then fills every board's readings, boards in
// parallel.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/module.h"
#include "framework/object_rows.h"
#include "framework/range_and_bearing_access.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/ray_cast.h"
#include "modules/range_and_bearing/range_and_bearing.h"

struct lua_State;

namespace swarmsim {
class LineOfSight;
}

namespace swarmsim::range_and_bearing {

inline constexpr const char* kModuleName = "range_and_bearing";

// sim.setRangeAndBearingData, sim.getRangeAndBearingData,
// sim.readRangeAndBearing (lua_api_range_and_bearing.cc).
void RegisterRangeAndBearingApi(lua_State* L);

// Also the plugins' access to the boards (framework/range_and_bearing_access.h).
class RangeAndBearingModule final : public Module, public RangeAndBearingAccess {
 public:
  // Snapshots (framework/world_state.h): nothing to save here: the boards' rows (type.cc: what they
  // send and heard) hold every state a step carries to the next; the indexes above are rebuilt each
  // sense phase.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Sense(World* world) override;
  int SetData(Scene* scene, int robot, ObjectId id, const uint8_t* data,
              size_t size) const noexcept override;
  int Read(const Scene& scene, ObjectId id, SwarmsimRangeAndBearingReading* out,
           int max) const noexcept override;

 private:
  struct Board {       // 40 bytes
    Vec3 p_W;          // its origin
    int32_t instance;  // its robot, or -1
    uint32_t slot;
    uint32_t row;
  };
  // A shape that may block: a robot's (robot_occlusion) or one of no
  // robot (occlusion).
  struct Occluder {
    proximity::PlacedShape shape;
    Vec3 lo, hi;       // its world bounds, grown for rounding
    double cx, cy, r;  // a circle about its (x, y) bounds
    uint32_t slot;
  };
  // The shapes of one kind, placed, and a grid over their footprints.
  struct ShapeIndex {
    std::vector<Occluder> shapes;
    std::vector<GridItem> items;  // their xy footprint circles (shapes)
    SpatialGrid grid;
    // The shapes whose footprint meets the disc (x, y, r) and whose
    // heights meet [z_lo, z_hi] (a receiver's range, the boards'
    // heights), but those `skip` says.
    template <class Skip>
    void List(double x, double y, double r, double z_lo, double z_hi, Skip skip,
              std::vector<uint32_t>* out) const;
  };
  // A listed occluder's footprint circle, packed for the per-segment test.
  struct Footprint {  // 32 bytes
    double cx, cy, r2;
    uint32_t shape;  // in its ShapeIndex
  };
  // A board in range of a receiver: its distance and index in boards_.
  struct Heard {
    double distance;
    uint32_t board;
  };

  void IndexBoards(const Scene& scene, const Rows<RangeAndBearingRow>& rows);
  // Places every shape of a robot (robots) and of no robot (statics).
  void IndexShapes(const Scene& scene, bool statics, bool robots);
  // Fills board `row`'s readings. Thread-safe across boards.
  void Hear(const Scene& scene, const Rows<RangeAndBearingRow>& rows, uint32_t row,
            RangeAndBearingRow* rab) const;
  // Does one of `statics` (shapes of no robot, but those either board hangs
  // from), or the map, or one of `robots` (but the sender's robot's: the
  // receiver's were left out) cross the segment between the boards?
  bool Blocked(const Scene& scene, const Board& from, const Board& to, double distance,
               const std::vector<Footprint>& statics, bool map,
               const std::vector<Footprint>& robots) const;

  uint64_t seed_ = 0;  // the world's
  int64_t step_ = 0;   // the step being sensed
  bool type_found_ = false;
  bool have_type_ = false;
  ObjectType type_{};
  const LineOfSight* line_of_sight_ = nullptr;  // the world's: asked for the map's voxels
  std::vector<Board> boards_;                   // every board (rows order)
  std::vector<GridItem> board_items_;           // their xy (boards_)
  SpatialGrid board_grid_;
  double z_lo_ = 0, z_hi_ = 0;  // the boards' heights (m)
  ShapeIndex statics_;          // shapes of no robot, when a board asks
  ShapeIndex robot_shapes_;     // robots' shapes, when a board asks
  bool have_statics_ = false, have_robot_shapes_ = false;
  bool have_map_ = false;  // the scene has a map: ask the line of sight
};

}  // namespace swarmsim::range_and_bearing
