// The range-and-bearing module (internal to modules/range_and_bearing): in
// the sense phase it indexes every board's position (and, if a board asks,
// the robots' shapes), then fills every board's readings, boards in
// parallel.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/module.h"
#include "framework/object_rows.h"
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

class RangeAndBearingModule final : public Module {
 public:
  void Sense(World* world) override;

 private:
  struct Board {       // 40 bytes
    Vec3 p_W;          // its origin
    int32_t instance;  // its robot, or -1
    uint32_t slot;
    uint32_t row;
  };
  // A robot's shape that may block (robot_occlusion).
  struct Occluder {
    proximity::PlacedShape shape;
    Vec3 lo, hi;  // its world bounds, grown for rounding
    uint32_t slot;
  };
  // A board in range of a receiver: its distance and index in boards_.
  struct Heard {
    double distance;
    uint32_t board;
  };

  void IndexBoards(const Scene& scene, const Rows<RangeAndBearingRow>& rows);
  void IndexRobotShapes(const Scene& scene);
  // Fills board `row`'s readings. Thread-safe across boards.
  void Hear(const Scene& scene, const Rows<RangeAndBearingRow>& rows, uint32_t row,
            RangeAndBearingRow* rab) const;
  // Does a static shape or the map (the world's line of sight), or, with
  // `robots`, one of `occluders` (but the two boards' robots') cross the
  // segment between the boards?
  bool Blocked(const Scene& scene, const Board& from, const Board& to, double distance,
               bool statics, bool robots, const std::vector<uint32_t>& occluders) const;

  uint64_t seed_ = 0;  // the world's
  int64_t step_ = 0;   // the step being sensed
  bool type_found_ = false;
  bool have_type_ = false;
  ObjectType type_{};
  const LineOfSight* line_of_sight_ = nullptr;  // the world's; null: nothing static blocks
  std::vector<Board> boards_;           // every board (rows order)
  std::vector<GridItem> board_items_;   // their xy (boards_)
  SpatialGrid board_grid_;
  std::vector<Occluder> occluders_;       // robots' shapes, when a board asks (occluders)
  std::vector<GridItem> occluder_items_;  // their xy footprint circles (occluders)
  SpatialGrid occluder_grid_;
  bool have_occluders_ = false;
};

}  // namespace swarmsim::range_and_bearing
