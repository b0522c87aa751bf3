// Delivery of the messages and signals sent in the last step (World::DeliverMessages).
//
// Messages are gathered from the robots' outboxes, stably sorted by sender
// handle, and each robot's inbox is then filled by its own task: global
// messages, the local and direct messages addressed to it (bucketed once,
// serially), and the range messages whose circle covers it, found through a
// spatial grid of the senders (radius = range). Cost: O(messages + receivers
// in range). Every inbox ends in message order, i.e. sender-handle order,
// whatever the thread count. The world's main script sends with a null
// sender (it has no object): first in that order, without distance or bearing.
#include <algorithm>
#include <cmath>

#include "framework/proximity_backend.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

// Robots per task when filling inboxes: a few grid queries each.
constexpr int64_t kReceiverGrain = 64;

}  // namespace

void World::ApplySignalWrites() {
  // Writes in robot order, then the scene's; the last write wins. Only
  // robots whose scripts wrote something (pending_) are visited.
  auto apply_signals = [&](RobotRuntime& rt) {
    for (auto& [name, value] : rt.signal_writes) {
      if (value) {
        signals_.insert_or_assign(std::move(name), std::move(*value));
      } else if (auto it = signals_.find(name); it != signals_.end()) {
        signals_.erase(it);
      }
    }
    rt.signal_writes.clear();
  };
  for (size_t r = 0; r < runtimes_.size(); ++r)
    if (pending_[r] & kPendingMessages) apply_signals(runtimes_[r]);
  apply_signals(scene_runtime_);
}

void World::DeliverMessages() {
  // Signals the scene's scripts wrote since the last control pass (a main
  // script after sim.handleChildScripts).
  ApplySignalWrites();
  // Only robots whose scripts wrote something (pending_) are visited.
  const int robot_count = static_cast<int>(runtimes_.size());
  std::vector<int> writers;
  for (int r = 0; r < robot_count; ++r)
    if (pending_[r] & kPendingMessages) {
      writers.push_back(r);
      pending_[r] &= ~kPendingMessages;
    }
  // Custom data written last step, robots in index order, then the scene's
  // scripts (the last write of a tag wins); objects removed since are skipped.
  auto apply_custom_data = [&](RobotRuntime& rt) {
    for (RobotRuntime::CustomDataWrite& w : rt.custom_data_writes)
      if (scene_.IsValid(w.object)) scene_.WriteCustomData(w.object, w.tag, std::move(w.data));
    rt.custom_data_writes.clear();
  };
  for (int r : writers) apply_custom_data(runtimes_[r]);
  apply_custom_data(scene_runtime_);

  // Gather in robot order, then the scene's; order by sender handle.
  ++message_round_;
  messages_.clear();
  auto gather = [&](RobotRuntime& rt) {
    for (Message& m : rt.outbox) messages_.push_back(std::move(m));
    rt.outbox.clear();
    rt.outbox_bytes = 0;
  };
  for (int r : writers) gather(runtimes_[r]);
  gather(scene_runtime_);
  if (messages_.empty()) {
    for (int r = 0; r < robot_count; ++r)
      if (pending_[r] & kPendingInbox) {
        runtimes_[r].inbox.clear();
        pending_[r] &= ~kPendingInbox;
      }
    scene_runtime_.inbox.clear();
    return;
  }
  // Gathered in robot order, which is usually sender-handle order already.
  const auto by_sender = [](const Message& a, const Message& b) { return a.sender < b.sender; };
  if (!std::is_sorted(messages_.begin(), messages_.end(), by_sender))
    std::stable_sort(messages_.begin(), messages_.end(), by_sender);

  // Per message: the sender's position; global ones listed, local and
  // direct ones bucketed by receiving robot (bucket robot_count: the scene),
  // range ones into the grid.
  const uint32_t message_count = static_cast<uint32_t>(messages_.size());
  const int scene_bucket = robot_count;
  message_origin_.resize(message_count);
  global_messages_.clear();
  message_bucket_start_.assign(robot_count + 2, 0);
  std::vector<int> receiver(message_count, -2);  // bucket of a local/direct message, else -2
  std::vector<GridItem> items;
  for (uint32_t m = 0; m < message_count; ++m) {
    const Message& msg = messages_[m];
    // The main script has no object: its messages have no origin. A sending
    // object removed meanwhile drops its messages.
    if (msg.sender.IsNull()) {
      message_origin_[m] = {};
    } else if (scene_.IsValid(msg.sender)) {
      message_origin_[m] = scene_.world_pose(msg.sender).p;
    } else {
      continue;
    }
    switch (msg.scope) {
      case MessageScope::kGlobal: global_messages_.push_back(m); break;
      case MessageScope::kLocal:
        receiver[m] = msg.sender_instance >= 0 ? msg.sender_instance : scene_bucket;
        break;
      case MessageScope::kDirect:
        if (scene_.IsValid(msg.target)) {
          const int instance = scene_.instance_of(msg.target);
          receiver[m] = instance >= 0 ? instance : scene_bucket;
        }
        break;
      case MessageScope::kRange:
        items.push_back({message_origin_[m].x, message_origin_[m].y, msg.range, m});
        break;
    }
    if (receiver[m] >= 0) ++message_bucket_start_[receiver[m] + 1];
  }
  for (int b = 0; b <= robot_count; ++b) message_bucket_start_[b + 1] += message_bucket_start_[b];
  message_bucket_.resize(message_bucket_start_[robot_count + 1]);
  {
    std::vector<uint32_t> fill(message_bucket_start_.begin(), message_bucket_start_.end() - 1);
    for (uint32_t m = 0; m < message_count; ++m)
      if (receiver[m] >= 0) message_bucket_[fill[receiver[m]]++] = m;
  }
  message_grid_.Build(items);

  // Each robot fills its own inbox.
  const auto& instances = scene_.instances();
  scheduler_->ParallelFor(0, robot_count, kReceiverGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      std::vector<ReceivedMessage>& inbox = runtimes_[r].inbox;
      inbox.clear();
      pending_[r] &= ~kPendingInbox;
      if (!instances[r].alive) continue;
      const Pose X_WR = scene_.world_pose(instances[r].root);
      const Pose X_RW = X_WR.Inverse();
      auto push = [&](uint32_t m) {
        if (messages_[m].sender.IsNull()) {  // from the main script: no distance or bearing
          inbox.push_back({m, false, 0, 0});
          return;
        }
        const Vec3 d = message_origin_[m] - X_WR.p;
        const Vec3 p_RS = X_RW * message_origin_[m];
        inbox.push_back(
            {m, true, std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::atan2(p_RS.y, p_RS.x)});
      };
      for (uint32_t m : global_messages_) push(m);
      for (uint32_t e = message_bucket_start_[r]; e < message_bucket_start_[r + 1]; ++e)
        push(message_bucket_[e]);
      const size_t sorted_end = inbox.size();
      if (!message_grid_.empty()) {
        message_grid_.ForEachInCircle(X_WR.p.x, X_WR.p.y, 0, [&](uint32_t, const GridItem& item) {
          const Message& msg = messages_[item.id];
          if (msg.sender_instance == r) return;
          const Vec3 d = message_origin_[item.id] - X_WR.p;
          if (d.x * d.x + d.y * d.y + d.z * d.z > msg.range * msg.range) return;
          if (msg.line_of_sight && proximity_ != nullptr &&
              proximity_->SegmentBlocked(message_origin_[item.id], X_WR.p))
            return;
          push(item.id);
        });
      }
      // Three ascending runs (global, addressed, range): one order.
      const auto by_message = [](const ReceivedMessage& a, const ReceivedMessage& b) {
        return a.message < b.message;
      };
      if (sorted_end > 0 && !global_messages_.empty())
        std::sort(inbox.begin(), inbox.begin() + static_cast<ptrdiff_t>(sorted_end), by_message);
      std::inplace_merge(inbox.begin(), inbox.begin() + static_cast<ptrdiff_t>(sorted_end),
                         inbox.end(), by_message);
      if (!inbox.empty()) pending_[r] |= kPendingInbox;
    }
  });

  // The scene's scripts: global messages and those addressed to them.
  std::vector<ReceivedMessage>& scene_inbox = scene_runtime_.inbox;
  scene_inbox.clear();
  for (uint32_t m : global_messages_) scene_inbox.push_back({m, false, 0, 0});
  for (uint32_t e = message_bucket_start_[scene_bucket];
       e < message_bucket_start_[scene_bucket + 1]; ++e)
    scene_inbox.push_back({message_bucket_[e], false, 0, 0});
  std::sort(
      scene_inbox.begin(), scene_inbox.end(),
      [](const ReceivedMessage& a, const ReceivedMessage& b) { return a.message < b.message; });
}

}  // namespace swarmsim
