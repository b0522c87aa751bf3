// Scene::SaveState, LoadState and AddStructure: the scene's part of a world
// snapshot (framework/world_state.h).
#include <algorithm>
#include <vector>

#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"

namespace swarmsim {

void Scene::AddStructure(StateHasher* hasher) const {
  // Whole arrays at once (a robot has ~30 objects: 30,000 slots hash in
  // well under a millisecond); names by their pool ids, which the same
  // loads give the same.
  const auto add = [hasher](const auto& values) {
    hasher->AddValue(values.size());
    hasher->Add(values.data(), values.size() * sizeof(values[0]));
  };
  add(alive_);
  add(type_);
  add(parent_);
  add(instance_);
  add(row_);
  add(motion_);
  add(name_);
  for (size_t t = 0; t < tables_.size(); ++t) {
    const size_t rows = tables_[t] ? tables_[t]->size() : 0;
    hasher->AddValue(rows);
    if (rows > 0) add(tables_[t]->owners);
  }
  hasher->AddValue(instances_.size());
  for (const ModelInstance& instance : instances_) hasher->AddValue(instance.alive);
}

void Scene::SaveState(StateWriter* out) const {
  out->bytes().reserve(out->bytes().size() + slot_count() * (2 * sizeof(Pose) + 1) +
                       motions_.size() * sizeof(Motion) + 4096);
  // Poses, velocities and the simulated flag of every live object.
  for (uint32_t s = 0; s < slot_count(); ++s) {
    if (alive_[s] == 0) continue;
    out->Put(X_PO_[s]);
    out->Put(X_WO_[s]);
    out->Put(simulated_[s]);
    if (motion_[s] != kNoMotion) out->Put(motions_[motion_[s]]);
  }
  // Custom data blocks, slots in order.
  std::vector<uint32_t> slots;
  for (const auto& [slot, blocks] : custom_data_) slots.push_back(slot);
  std::sort(slots.begin(), slots.end());
  out->Put<uint64_t>(slots.size());
  for (const uint32_t slot : slots) {
    const CustomData& blocks = custom_data_.at(slot);
    out->Put(slot);
    out->Put<uint64_t>(blocks.size());
    for (const auto& [tag, block] : blocks) {
      out->PutString(tag);
      out->PutString(block.data);
    }
  }
}

void Scene::LoadState(StateReader* in) {
  for (uint32_t s = 0; s < slot_count(); ++s) {
    if (alive_[s] == 0) continue;
    X_PO_[s] = in->Get<Pose>();
    X_WO_[s] = in->Get<Pose>();
    simulated_[s] = in->Get<uint8_t>();
    if (motion_[s] != kNoMotion) motions_[motion_[s]] = in->Get<Motion>();
  }
  std::vector<uint32_t> old;
  for (const auto& [slot, blocks] : custom_data_) old.push_back(slot);
  for (const uint32_t slot : old) DropCustomData(slot);
  const uint64_t count = in->GetCount(sizeof(uint32_t) + sizeof(uint64_t));
  for (uint64_t i = 0; i < count; ++i) {
    const uint32_t slot = in->Get<uint32_t>();
    if (slot >= slot_count() || alive_[slot] == 0)
      in->Fail("custom data of object slot " + std::to_string(slot) + ", which is not there");
    const uint64_t blocks = in->GetCount(2 * sizeof(uint64_t));
    for (uint64_t b = 0; b < blocks; ++b) {
      std::string tag = in->GetString();
      custom_data_[slot][std::move(tag)].data = in->GetString();
    }
  }
}

}  // namespace swarmsim
