// The IR messaging module (internal to modules/ir_messaging): in the sense
// phase it decides which queued messages go out and when, then fills every
// transceiver's inbox, transceivers in parallel (module.cc).
#pragma once

#include <cstdint>
#include <vector>

#include "framework/device_access.h"
#include "framework/module.h"
#include "framework/object_rows.h"
#include "modules/ir_messaging/ir_messaging.h"

struct lua_State;

namespace swarmsim::ir_messaging {

inline constexpr const char* kModuleName = "ir_messaging";

// sim.sendIrMessage, sim.readIrMessages, sim.getIrSent (lua_api_ir_messaging.cc).
void RegisterIrMessagingApi(lua_State* L);

// Also the plugins' access to the transceivers (framework/device_access.h).
class IrMessagingModule final : public Module, public IrAccess {
 public:
  // Snapshots (framework/world_state.h): nothing to save here: the transceivers' rows (type.cc:
  // queued messages, what they heard) hold every state a step carries to the next; the indexes
  // above are rebuilt each sense phase.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Start(World* world) override;
  void Sense(World* world) override;
  int Send(Scene* scene, int robot, ObjectId id, const uint8_t* data,
           size_t size) const noexcept override;
  int Sent(const Scene& scene, ObjectId id) const noexcept override;
  int Receive(const Scene& scene, ObjectId id, SwarmsimIrMessage* out,
              int max) const noexcept override;

 private:
  // A queued message: its transceiver, where it is and when it is on the air.
  struct Transmission {  // 64 bytes
    double x, y, z;      // the sender's origin (m, world)
    double start, end;   // s from the start of the step: on the air in [start, end)
    double range;        // the sender's own range (what it hears, for carrier sense)
    int32_t instance;    // its robot, or -1
    uint32_t slot;
    uint32_t row;
    bool carrier_sense;
  };
  // A transmission a receiver is in range of: its index in on_air_ and the distance.
  struct Heard {
    uint32_t index;
    double distance;
  };
  // A uniform grid over the (x, y) of `items` (cells of at least the
  // largest range: a receiver's 3 x 3 block of cells holds every sender
  // within its range), as CSR arrays.
  struct Grid {
    // An item's position and index, stored by cell: a query reads memory in order.
    struct Point {  // 32 bytes
      double x, y, z;
      uint32_t index;
    };
    double x0 = 0, y0 = 0, inv_cell = 1;
    int cells_x = 0, cells_y = 0;
    std::vector<uint32_t> start;  // first entry of each cell (cells + 1)
    std::vector<Point> points;    // by cell, ascending index in a cell
    std::vector<uint32_t> fill_;  // build scratch
    void Build(const std::vector<Transmission>& t, double cell);
    // Calls visit(point) for every item in the 3 x 3 cells about (x, y).
    template <class Visit>
    void Near(double x, double y, Visit&& visit) const;
  };

  // The row of transceiver `id`, or null if it is not one.
  IrTransceiverRow* Find(const Scene& scene, ObjectId id) const noexcept;
  // Draws each queued message's start time and decides which go out.
  void Transmit(double time_step);
  // Fills row `row`'s inbox. Thread-safe across rows.
  void Hear(const Scene& scene, const Rows<IrTransceiverRow>& rows, uint32_t row,
            IrTransceiverRow* ir) const;

  uint64_t seed_ = 0;       // the world's
  int64_t step_ = 0;        // the step being sensed
  bool have_type_ = false;  // the scene has the type (found at Start)
  ObjectType type_{};
  Rows<IrTransceiverRow>* scene_rows_ = nullptr;  // the scene's, while sensing
  double max_range_ = 0;                          // the largest range of a transceiver
  std::vector<Transmission> queued_;  // this step's queued messages, then sorted by start
  std::vector<Transmission> on_air_;  // those that went out, by start time (then slot)
  std::vector<uint8_t> went_out_;     // per queued_: it went out
  Grid grid_;                         // over queued_, then over on_air_
};

}  // namespace swarmsim::ir_messaging
