// Delivery of the messages, signals and custom data written in the last step
// (Messaging::Deliver).
//
// Messages are gathered from the robots' outboxes, stably sorted by sender
// handle, and each robot's inbox is then filled by its own task: global
// messages, the local and direct messages addressed to it (bucketed once,
// serially), and the range messages whose circle covers it, found through a
// spatial grid of the senders (radius = range). Cost: O(messages + receivers
// in range). Every inbox ends in message order, i.e. sender-handle order,
// whatever the thread count. The world's main script sends with a null
// sender (it has no object): first in that order, without distance or bearing.
#include "framework/messaging.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <variant>

#include "framework/line_of_sight.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/script_memory.h"
#include "framework/state_hash.h"

namespace swarmsim {
namespace {

// Robots per task when filling inboxes: a few grid queries each.
constexpr int64_t kReceiverGrain = 64;

void Release(ScriptMemory* memory, uint64_t bytes) {
  if (memory != nullptr) memory->Release(bytes);
}

// A signal's charge (value null: a clear).
uint64_t SignalValueBytes(const std::string& name, const ParamValue* value) {
  const std::string* text = value != nullptr ? std::get_if<std::string>(value) : nullptr;
  return SignalBytes(name.size(), text != nullptr ? text->size() : 0);
}
uint64_t SignalWriteBytes(const std::string& name, const std::optional<ParamValue>& value) {
  return SignalValueBytes(name, value ? &*value : nullptr);
}

}  // namespace

void Messaging::Resize(int robot_count) {
  robots_.resize(robot_count);
  pending_.resize(robot_count, 0xff);  // new robots: look at everything once
}

void Messaging::ClearRobot(int robot) {
  RobotMail& mail = robots_.at(robot);
  // What it held goes, and so does its charge.
  for (const Message& m : mail.outbox) Release(mail.memory, MessageBytes(m.data));
  for (const auto& [name, value] : mail.signal_writes)
    Release(mail.memory, SignalWriteBytes(name, value));
  for (const RobotMail::CustomDataWrite& w : mail.custom_data_writes)
    Release(mail.memory, CustomDataBytes(w.tag.size(), w.data.size()));
  ScriptMemory* memory = mail.memory;
  mail = RobotMail();
  mail.memory = memory;
  pending_[robot] = 0;
}

void Messaging::MarkAllPending() { pending_.assign(robots_.size(), 0xff); }

void Messaging::ApplySignalWrites() {
  // Writes in robot order, then the scene's; the last write wins. Only
  // robots whose scripts wrote something (pending_) are visited.
  // A write's charge becomes its signal's; the value it replaces, or a
  // clear, releases the old charge.
  auto apply_signals = [&](RobotMail& mail) {
    for (auto& [name, value] : mail.signal_writes) {
      auto it = signals_.find(name);
      if (it != signals_.end()) {
        Release(it->second.owner, SignalValueBytes(it->first, &it->second.value));
        if (!value) signals_.erase(it);
      }
      if (!value) {
        Release(mail.memory, SignalWriteBytes(name, value));
      } else if (it != signals_.end()) {
        it->second = {std::move(*value), mail.memory};
      } else {
        signals_.emplace(std::move(name), Signal{std::move(*value), mail.memory});
      }
    }
    mail.signal_writes.clear();
  };
  for (size_t r = 0; r < robots_.size(); ++r)
    if (pending_[r] & kPendingWrites) apply_signals(robots_[r]);
  apply_signals(scene_);
}

void Messaging::Deliver(Scene* scene, const LineOfSight* line_of_sight, TaskScheduler& scheduler) {
  // Signals the scene's scripts wrote since the last control pass (a main
  // script after sim.handleChildScripts).
  ApplySignalWrites();
  const std::vector<int> writers = TakeWriters();
  ApplyCustomDataWrites(writers, scene);
  GatherMessages(writers);
  if (messages_.empty()) {
    ClearInboxes();
    return;
  }
  IndexMessages(*scene);
  FillRobotInboxes(*scene, line_of_sight, scheduler);
  FillSceneInbox();
}

std::vector<int> Messaging::TakeWriters() {
  // Only robots whose scripts wrote something (pending_) are visited.
  const int robot_count = static_cast<int>(robots_.size());
  std::vector<int> writers;
  for (int r = 0; r < robot_count; ++r)
    if (pending_[r] & kPendingWrites) {
      writers.push_back(r);
      pending_[r] &= ~kPendingWrites;
    }
  return writers;
}

void Messaging::ApplyCustomDataWrites(const std::vector<int>& writers, Scene* scene) {
  // Custom data written last step, robots in index order, then the scene's
  // scripts (the last write of a tag wins); objects removed since are skipped.
  auto apply_custom_data = [&](RobotMail& mail) {
    for (RobotMail::CustomDataWrite& w : mail.custom_data_writes) {
      if (scene->IsValid(w.object))
        scene->WriteCustomData(w.object, w.tag, std::move(w.data), mail.memory);
      else
        Release(mail.memory, CustomDataBytes(w.tag.size(), w.data.size()));
    }
    mail.custom_data_writes.clear();
  };
  for (int r : writers) apply_custom_data(robots_[r]);
  apply_custom_data(scene_);
}

void Messaging::GatherMessages(const std::vector<int>& writers) {
  // Gather in robot order, then the scene's; order by sender handle.
  ++round_;
  // The last step's messages go: their senders' charges with them.
  for (const Message& m : messages_)
    Release(m.sender_instance >= 0 ? robots_[m.sender_instance].memory : scene_.memory,
            MessageBytes(m.data));
  messages_.clear();
  auto gather = [&](RobotMail& mail) {
    for (Message& m : mail.outbox) messages_.push_back(std::move(m));
    mail.outbox.clear();
  };
  for (int r : writers) gather(robots_[r]);
  gather(scene_);
  // Gathered in robot order, which is usually sender-handle order already.
  const auto by_sender = [](const Message& a, const Message& b) { return a.sender < b.sender; };
  if (!std::is_sorted(messages_.begin(), messages_.end(), by_sender))
    std::stable_sort(messages_.begin(), messages_.end(), by_sender);
}

void Messaging::ClearInboxes() {
  for (size_t r = 0; r < robots_.size(); ++r)
    if (pending_[r] & kPendingInbox) {
      robots_[r].inbox.clear();
      pending_[r] &= ~kPendingInbox;
    }
  scene_.inbox.clear();
}

void Messaging::IndexMessages(const Scene& scene) {
  // Per message: the sender's position; global ones listed, local and
  // direct ones bucketed by receiving robot (bucket robot_count: the scene),
  // range ones into the grid.
  const int robot_count = static_cast<int>(robots_.size());
  const uint32_t message_count = static_cast<uint32_t>(messages_.size());
  const int scene_bucket = robot_count;
  origin_.resize(message_count);
  global_.clear();
  bucket_start_.assign(robot_count + 2, 0);
  std::vector<int> receiver(message_count, -2);  // bucket of a local/direct message, else -2
  std::vector<GridItem> items;
  for (uint32_t m = 0; m < message_count; ++m) {
    const Message& msg = messages_[m];
    // The main script has no object: its messages have no origin. A sending
    // object removed meanwhile drops its messages.
    if (msg.sender.IsNull()) {
      origin_[m] = {};
    } else if (scene.IsValid(msg.sender)) {
      origin_[m] = scene.world_pose(msg.sender).p;
    } else {
      continue;
    }
    switch (msg.scope) {
      case MessageScope::kGlobal: global_.push_back(m); break;
      case MessageScope::kLocal:
        receiver[m] = msg.sender_instance >= 0 ? msg.sender_instance : scene_bucket;
        break;
      case MessageScope::kDirect:
        if (scene.IsValid(msg.target)) {
          const int instance = scene.instance_of(msg.target);
          receiver[m] = instance >= 0 ? instance : scene_bucket;
        }
        break;
      case MessageScope::kRange: items.push_back({origin_[m].x, origin_[m].y, msg.range, m}); break;
    }
    if (receiver[m] >= 0) ++bucket_start_[receiver[m] + 1];
  }
  for (int b = 0; b <= robot_count; ++b) bucket_start_[b + 1] += bucket_start_[b];
  bucket_.resize(bucket_start_[robot_count + 1]);
  {
    std::vector<uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
    for (uint32_t m = 0; m < message_count; ++m)
      if (receiver[m] >= 0) bucket_[fill[receiver[m]]++] = m;
  }
  grid_.Build(items);
}

void Messaging::FillRobotInboxes(const Scene& scene, const LineOfSight* line_of_sight,
                                 TaskScheduler& scheduler) {
  // Each robot fills its own inbox.
  const int robot_count = static_cast<int>(robots_.size());
  const auto& instances = scene.instances();
  scheduler.ParallelFor(0, robot_count, kReceiverGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      std::vector<ReceivedMessage>& inbox = robots_[r].inbox;
      inbox.clear();
      pending_[r] &= ~kPendingInbox;
      if (!instances[r].alive) continue;
      const Pose X_WR = scene.world_pose(instances[r].root);
      const Pose X_RW = X_WR.Inverse();
      auto push = [&](uint32_t m) {
        if (messages_[m].sender.IsNull()) {  // from the main script: no distance or bearing
          inbox.push_back({m, false, 0, 0});
          return;
        }
        const Vec3 d = origin_[m] - X_WR.p;
        const Vec3 p_RS = X_RW * origin_[m];
        inbox.push_back(
            {m, true, std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::atan2(p_RS.y, p_RS.x)});
      };
      for (uint32_t m : global_) push(m);
      for (uint32_t e = bucket_start_[r]; e < bucket_start_[r + 1]; ++e) push(bucket_[e]);
      const size_t sorted_end = inbox.size();
      if (!grid_.empty()) {
        grid_.ForEachInCircle(X_WR.p.x, X_WR.p.y, 0, [&](uint32_t, const GridItem& item) {
          const Message& msg = messages_[item.id];
          if (msg.sender_instance == r) return;
          const Vec3 d = origin_[item.id] - X_WR.p;
          if (d.x * d.x + d.y * d.y + d.z * d.z > msg.range * msg.range) return;
          if (msg.line_of_sight && line_of_sight != nullptr &&
              line_of_sight->SegmentBlocked(origin_[item.id], X_WR.p))
            return;
          push(item.id);
        });
      }
      // Three ascending runs (global, addressed, range): one order.
      const auto by_message = [](const ReceivedMessage& a, const ReceivedMessage& b) {
        return a.message < b.message;
      };
      if (sorted_end > 0 && !global_.empty())
        std::sort(inbox.begin(), inbox.begin() + static_cast<ptrdiff_t>(sorted_end), by_message);
      std::inplace_merge(inbox.begin(), inbox.begin() + static_cast<ptrdiff_t>(sorted_end),
                         inbox.end(), by_message);
      if (!inbox.empty()) pending_[r] |= kPendingInbox;
    }
  });
}

void Messaging::FillSceneInbox() {
  // The scene's scripts: global messages and those addressed to them.
  const int scene_bucket = static_cast<int>(robots_.size());
  std::vector<ReceivedMessage>& scene_inbox = scene_.inbox;
  scene_inbox.clear();
  for (uint32_t m : global_) scene_inbox.push_back({m, false, 0, 0});
  for (uint32_t e = bucket_start_[scene_bucket]; e < bucket_start_[scene_bucket + 1]; ++e)
    scene_inbox.push_back({bucket_[e], false, 0, 0});
  std::sort(
      scene_inbox.begin(), scene_inbox.end(),
      [](const ReceivedMessage& a, const ReceivedMessage& b) { return a.message < b.message; });
}

void Messaging::HashState(StateHasher* h) const {
  auto add_text = [h](const std::string& text) {
    h->AddValue(text.size());
    h->Add(text.data(), text.size());
  };
  for (const auto& [name, signal] : signals_) {
    add_text(name);
    add_text(ParamToString(signal.value));
  }
  auto add_pending = [&](const RobotMail& mail) {
    for (const Message& m : mail.outbox) {
      add_text(m.data);
      h->AddValue(m.sender);
      h->AddValue(m.target);
      h->AddValue(m.range);
      h->AddValue(m.scope);
    }
    for (const auto& [name, value] : mail.signal_writes) {
      add_text(name);
      add_text(value ? ParamToString(*value) : std::string("<cleared>"));
    }
    for (const RobotMail::CustomDataWrite& w : mail.custom_data_writes) {
      h->AddValue(w.object);
      add_text(w.tag);
      add_text(w.data);
    }
  };
  for (const RobotMail& mail : robots_) add_pending(mail);
  add_pending(scene_);
}

}  // namespace swarmsim
