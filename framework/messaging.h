// Messaging between scripts: messages (sim.send*Message), signals
// (sim.setSignal) and custom-data writes (sim.writeCustomDataBlock). What the
// scripts send and write in one step is applied and delivered at the start
// of the next (signals as soon as a control pass ends), in an order that does
// not depend on the thread count. The World owns one Messaging and calls it
// at those points; the sim.* functions (lua_api_messages.cc,
// lua_api_custom_data.cc) write to their robot's RobotMail and read the
// delivered messages and the signals here.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/parameters.h"
#include "framework/spatial_grid.h"

namespace swarmsim {

class LineOfSight;
class Scene;
class ScriptMemory;
class StateHasher;
class TaskScheduler;

// A message sent by a script (sim.send*Message), delivered at the start of
// the next step in sender-handle order.
enum class MessageScope : uint8_t { kGlobal, kLocal, kDirect, kRange };
struct Message {
  std::string data;
  ObjectId sender;           // object carrying the sending script
  ObjectId target;           // kDirect: object carrying the receiving script
  int sender_instance = -1;  // robot of the sender, -1 for the scene
  double range = 0;          // m, kRange
  MessageScope scope = MessageScope::kGlobal;
  bool line_of_sight = false;  // kRange: only receivers the static environment does not hide
};
// One message in a robot's inbox.
struct ReceivedMessage {      // 32 bytes
  uint32_t message = 0;       // index into Messaging::messages()
  bool has_geometry = false;  // false for scene receivers
  double distance = 0;        // m, from the receiver's model root to the sender
  double bearing = 0;         // rad, of the sender in the receiver's root frame (0 = +x, CCW)
};

// What one message is charged to its sender's ScriptMemory, from the time
// it is sent until the next step's messages are delivered.
inline uint64_t MessageBytes(const std::string& data) { return data.size() + sizeof(Message); }

// The mail of one robot's scripts, or of the scene's (and the main
// script's). Only the worker running that robot touches it during a phase.
// What it holds is charged to `memory` (the writer's): messages by
// MessageBytes, signal writes by SignalBytes, custom-data writes by
// CustomDataBytes (framework/script_memory.h); Messaging passes the charge
// on to the signal or block written, or releases it.
struct RobotMail {
  ScriptMemory* memory = nullptr;      // the robot's (the World's), or null: nothing charged
  std::vector<Message> outbox;         // messages sent this step
  std::vector<ReceivedMessage> inbox;  // messages delivered this step, sender-handle order
  // sim.setSignal/clearSignal writes (nullopt clears), applied at the next step.
  std::vector<std::pair<std::string, std::optional<ParamValue>>> signal_writes;
  // sim.writeCustomDataBlock writes (object, tag, data; empty data removes),
  // applied at the next step like signals.
  struct CustomDataWrite {
    ObjectId object;
    std::string tag;
    std::string data;
  };
  std::vector<CustomDataWrite> custom_data_writes;

  // Something for Messaging to gather: messages, signal or custom-data writes.
  bool has_writes() const {
    return !outbox.empty() || !signal_writes.empty() || !custom_data_writes.empty();
  }
};

// A signal's value, and the account of the script that wrote it (null:
// set from C++, not charged).
struct Signal {
  ParamValue value;
  ScriptMemory* owner = nullptr;
};

class Messaging {
 public:
  // Mail for robots 0 .. robot_count - 1 (robots are only added).
  void Resize(int robot_count);
  void Reserve(size_t robot_count) {
    robots_.reserve(robot_count);
    pending_.reserve(robot_count);
  }
  RobotMail& robot_mail(int robot) { return robots_[robot]; }
  // A removed robot: its inbox, unsent messages and writes are dropped.
  void ClearRobot(int robot);
  RobotMail& scene_mail() { return scene_; }

  // Call after robot `robot`'s scripts ran, on its worker: the serial passes
  // (ApplySignalWrites, Deliver) then visit only the robots that wrote.
  void NoteWrites(int robot) {
    if (robots_[robot].has_writes()) pending_[robot] |= kPendingWrites;
  }
  // Every robot may have written or received something (after sysCall_init).
  void MarkAllPending();

  // Signal writes, robots in index order, then the scene's scripts; the last
  // write wins. World calls it when a control pass ends.
  void ApplySignalWrites();
  // Start of a step: applies what the scripts wrote in the last one (signal
  // writes, then custom data to `scene`, robots in index order, then the
  // scene's scripts) and fills every inbox with the messages sent (see
  // messaging.cc). `line_of_sight` (may be null: nothing blocks) answers
  // range messages that need line of sight.
  void Deliver(Scene* scene, const LineOfSight* line_of_sight, TaskScheduler& scheduler);

  // Adds to `h` what the scripts left for the next step: the signals, then
  // each robot's messages, signal and custom-data writes not yet delivered
  // (robots in index order, then the scene's scripts).
  void HashState(StateHasher* h) const;
  // No signal set and nothing sent or written for the next step (a
  // snapshot saves nothing of the messaging then: world_state.h).
  bool Quiet() const {
    if (!signals_.empty() || scene_.has_writes()) return false;
    for (const RobotMail& mail : robots_)
      if (mail.has_writes()) return false;
    return true;
  }

  // Messages delivered this step (RobotMail::inbox indexes into it).
  const std::vector<Message>& messages() const { return messages_; }
  // Bumped each time the inboxes are refilled.
  uint64_t round() const { return round_; }
  // Signal values: the scripts' writes are applied when a control pass ends
  // (robots in index order, then the scene's scripts; the last write wins).
  const std::map<std::string, Signal, std::less<>>& signals() const { return signals_; }

 private:
  // Robots whose scripts wrote mail since the last Deliver, in index order;
  // their kPendingWrites bits are cleared.
  std::vector<int> TakeWriters();
  void ApplyCustomDataWrites(const std::vector<int>& writers, Scene* scene);
  // The writers' outboxes, then the scene's, into messages_ by sender handle.
  void GatherMessages(const std::vector<int>& writers);
  // No messages this step: every inbox that holds some is emptied.
  void ClearInboxes();
  // The origin of each message; global ones listed, local and direct ones
  // bucketed by receiving robot, range ones into the grid.
  void IndexMessages(const Scene& scene);
  void FillRobotInboxes(const Scene& scene, const LineOfSight* line_of_sight,
                        TaskScheduler& scheduler);
  void FillSceneInbox();

  // Per robot, whether its mail may hold something (the serial passes visit
  // only those robots instead of 10,000 empty ones).
  static constexpr uint8_t kPendingWrites = 1;  // outbox, signal and custom-data writes
  static constexpr uint8_t kPendingInbox = 2;   // inbox (set by Deliver)
  std::vector<uint8_t> pending_;                // by robot

  std::vector<RobotMail> robots_;  // by robot
  RobotMail scene_;                // the scene's scripts and the main script
  std::vector<Message> messages_;
  uint64_t round_ = 0;
  std::map<std::string, Signal, std::less<>> signals_;
  SpatialGrid grid_;                    // range messages, rebuilt each step
  std::vector<uint32_t> bucket_start_;  // local/direct messages per robot (robots + 2)
  std::vector<uint32_t> bucket_;        // message indices, grouped by receiving robot
  std::vector<uint32_t> global_;        // indices of global messages
  std::vector<Vec3> origin_;            // sender position per message (messages)
};

}  // namespace swarmsim
