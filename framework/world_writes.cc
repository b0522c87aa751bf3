// What Python writes into a world between steps that the scene alone does not
// carry: robots' velocities handed to the dynamics backend
// (World::SetVelocities), and model parameters set after load
// (World::WriteInstanceParameters), which then join the state hash and
// snapshots. A world nobody writes to hashes and saves as before: the golden
// hashes (tests/data/golden_hashes.tsv) do not move.
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "framework/world_state.h"

namespace swarmsim {

void World::SetVelocities(std::span<const int> robots, std::span<const Vec3> v_W,
                          std::span<const Vec3> w_W) {
  if (robots.size() != v_W.size() || robots.size() != w_W.size())
    throw Error("set_velocities: " + std::to_string(robots.size()) + " robots, " +
                std::to_string(v_W.size()) + " linear and " + std::to_string(w_W.size()) +
                " angular velocities");
  if (!started_) Start();
  // Checked whole first: each robot alive, its root a shape.
  for (const int robot : robots) {
    if (robot < 0 || static_cast<size_t>(robot) >= scene_.instances().size() ||
        !scene_.instance(robot).alive)
      throw Error("set_velocities: robot " + std::to_string(robot) + " is not in the world");
    const uint32_t root = scene_.SlotOf(scene_.instance(robot).root);
    if (scene_.type_at(root) != ObjectType::kShape)
      throw Error("set_velocities: robot '" + scene_.instance(robot).name +
                  "' has no body: its root object is not a shape");
  }
  // Every shape of each robot: v = v_root + w x (p - p_root).
  std::vector<uint32_t> slots;
  for (size_t i = 0; i < robots.size(); ++i) {
    const ModelInstance& robot = scene_.instance(robots[i]);
    const Vec3 p_root = scene_.world_pose(robot.root).p;
    for (const uint32_t s : robot.objects) {
      if (!scene_.alive_at(s)) continue;
      const Vec3 r = scene_.world_pose_at(s).p - p_root;
      if (scene_.SetVelocityAt(s, v_W[i] + w_W[i].Cross(r), w_W[i])) slots.push_back(s);
    }
  }
  if (!dynamics_->TakeVelocities(&scene_, slots)) RebuildDynamics();
}

void World::WriteInstanceParameters(int instance, SharedParameters parameters) {
  EnsureRuntimes();
  RobotRuntime& rt = runtimes_.at(static_cast<size_t>(instance));
  loaded_parameters_.try_emplace(instance, rt.parameters);  // the first write keeps the loaded
  rt.parameters = std::move(parameters);
}

namespace {

void AddParameter(StateHasher* h, const std::string& name, const ParamValue& value) {
  h->Add(name.data(), name.size() + 1);
  h->AddValue(static_cast<uint8_t>(value.index()));
  if (const double* d = std::get_if<double>(&value)) h->AddValue(*d);  // every bit
  if (const bool* b = std::get_if<bool>(&value)) h->AddValue(static_cast<uint8_t>(*b));
  if (const std::string* t = std::get_if<std::string>(&value)) h->Add(t->data(), t->size() + 1);
}

}  // namespace

void World::HashWrittenParameters(StateHasher* hasher) const {
  for (const auto& [robot, loaded] : loaded_parameters_) {
    if (!scene_.instances()[static_cast<size_t>(robot)].alive) continue;
    const SharedParameters& now = runtimes_[static_cast<size_t>(robot)].parameters;
    // Set back to the loaded values: as never written.
    if (now == loaded || (now && loaded && *now == *loaded)) continue;
    hasher->AddValue(robot);
    hasher->AddValue(now ? now->size() : size_t{0});
    if (now)
      for (const auto& [name, value] : *now) AddParameter(hasher, name, value);
  }
}

// Written: a count, then per robot its index and every parameter (name, kind
// 0 number, 1 boolean, 2 text, value).
void World::SaveWrittenParameters(StateWriter* out) const {
  out->Put<uint64_t>(loaded_parameters_.size());
  for (const auto& [robot, loaded] : loaded_parameters_) {
    out->Put<int32_t>(robot);
    const SharedParameters& now = runtimes_[static_cast<size_t>(robot)].parameters;
    out->Put<uint64_t>(now ? now->size() : 0);
    if (!now) continue;
    for (const auto& [name, value] : *now) {
      out->PutString(name);
      out->Put<uint8_t>(static_cast<uint8_t>(value.index()));
      if (const double* d = std::get_if<double>(&value)) out->Put(*d);
      if (const bool* b = std::get_if<bool>(&value)) out->Put<uint8_t>(*b);
      if (const std::string* t = std::get_if<std::string>(&value)) out->PutString(*t);
    }
  }
}

void World::LoadWrittenParameters(StateReader* in) {
  // Read whole first, then: robots written here but not in the snapshot get
  // their loaded parameters back, the snapshot's get theirs.
  std::map<int, SharedParameters> written;
  const uint64_t robots = in->GetCount(sizeof(int32_t) + sizeof(uint64_t));
  for (uint64_t k = 0; k < robots; ++k) {
    const auto robot = in->Get<int32_t>();
    if (robot < 0 || static_cast<size_t>(robot) >= runtimes_.size())
      in->Fail("parameters of robot " + std::to_string(robot) + ", which is not there");
    auto set = std::make_shared<ParameterSet>();
    const uint64_t count = in->GetCount(sizeof(uint64_t) + 1);
    for (uint64_t j = 0; j < count; ++j) {
      std::string name = in->GetString();
      const auto kind = in->Get<uint8_t>();
      ParamValue value;
      if (kind == 0)
        value = in->Get<double>();
      else if (kind == 1)
        value = in->GetBool();
      else if (kind == 2)
        value = in->GetString();
      else
        in->Fail("a parameter of kind " + std::to_string(kind));
      (*set)[std::move(name)] = std::move(value);
    }
    written[robot] = std::move(set);
  }
  for (auto it = loaded_parameters_.begin(); it != loaded_parameters_.end();) {
    if (written.count(it->first) == 0) {
      runtimes_[static_cast<size_t>(it->first)].parameters = it->second;
      it = loaded_parameters_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto& [robot, set] : written) WriteInstanceParameters(robot, std::move(set));
}

}  // namespace swarmsim
