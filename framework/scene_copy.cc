// Scene: copy-paste of subtrees (with their rows through each type's
// copy rule, scripts, model marks and dummy links) and the size factor
// (each type's scale rule). scene.cc has the rest of the scene.
#include <algorithm>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/prefault.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/script_memory.h"
#include "framework/shared_settings.h"

namespace swarmsim {
namespace {

// A copy's sources by slot: the index of a source (where its copy goes) from
// its slot, through a sorted list (a robot's ~30 objects: no hash table per
// copy).
class SourceIndex {
 public:
  explicit SourceIndex(std::span<const uint32_t> sources) : by_slot_(sources.size()) {
    for (uint32_t i = 0; i < sources.size(); ++i) by_slot_[i] = {sources[i], i};
    std::sort(by_slot_.begin(), by_slot_.end());
  }
  // The index of the source at `slot`; -1 for no slot (-1) or one outside.
  int32_t operator()(int64_t slot) const {
    if (slot < 0) return -1;
    const auto it = std::lower_bound(by_slot_.begin(), by_slot_.end(),
                                     std::pair<uint32_t, uint32_t>{uint32_t(slot), 0});
    return it != by_slot_.end() && it->first == slot ? static_cast<int32_t>(it->second) : -1;
  }

 private:
  std::vector<std::pair<uint32_t, uint32_t>> by_slot_;  // (slot, index)
};

}  // namespace

// --- Duplication ----------------------------------------------------------------------

uint32_t Scene::CopyObject(uint32_t src, int32_t new_parent, const Pose& X_PO) {
  // DuplicateSubtrees writes what this and AllocateSlotNamed write, for a
  // batch of copies at once: a column added here goes there too
  // (SceneTest.CopiesMadeTogetherAreTheCopiesMadeOneByOne compares them).
  // The copy's row from the source's, through the type's copy rule. The
  // pose is a copy: AllocateSlot may grow (and move) the arrays.
  const ObjectType type = type_[src];
  names_.Retain(name_[src]);
  const uint32_t slot = AllocateSlotNamed(name_[src], new_parent, X_PO, type);
  if (RowTable* table = tables_[static_cast<size_t>(type)].get())
    row_[slot] = table->AppendCopy(row_[src], slot, types_[static_cast<size_t>(type)]->copy_row);
  if (motion_[src] != kNoMotion && motion_[slot] != kNoMotion)
    motions_[motion_[slot]] = motions_[motion_[src]];
  model_root_[slot] = model_root_[src];
  if (const auto factor = size_factor_.find(src); factor != size_factor_.end())
    size_factor_[slot] = factor->second;
  if (const auto data = custom_data_.empty() ? custom_data_.end() : custom_data_.find(src);
      data != custom_data_.end()) {
    // Each block a script wrote is charged again to its writer (the run's
    // limit was checked by DuplicateSubtree).
    CustomData copy = data->second;  // (inserting may rehash)
    const CustomData& blocks = custom_data_[slot] = std::move(copy);
    for (const auto& [tag, block] : blocks)
      if (block.writer != nullptr)
        block.writer->Force(CustomDataBytes(tag.size(), block.data.size()));
  }
  if (script_[src] >= 0 && scripts_[script_[src]].source) {
    const ScriptAttachment attachment = scripts_[script_[src]];
    script_[slot] = static_cast<int32_t>(scripts_.size());
    scripts_.push_back(attachment);
  }
  return slot;
}

void Scene::ReserveForCopies(ObjectId root, size_t copies, Prefault* prefault) {
  std::vector<uint32_t> sub;
  CollectSubtree(SlotOf(root), &sub);
  std::vector<size_t> rows_of_type(types_.size(), 0);
  size_t scripts = 0;
  for (uint32_t s : sub) {
    ++rows_of_type[static_cast<size_t>(type_[s])];
    scripts += script_[s] >= 0;
  }
  const size_t slots = generation_.size() + sub.size() * copies;
  for (auto* v : {&X_PO_, &X_WO_}) v->reserve(slots);
  const size_t shapes = rows_of_type[static_cast<size_t>(ObjectType::kShape)];
  motions_.reserve(motions_.size() + shapes * copies);
  motion_.reserve(slots);
  for (auto* v : {&parent_, &first_child_, &last_child_, &next_sibling_, &prev_sibling_, &instance_,
                  &script_})
    v->reserve(slots);
  for (auto* v : {&simulated_, &alive_, &model_root_}) v->reserve(slots);
  type_.reserve(slots);
  row_.reserve(slots);
  generation_.reserve(slots);
  name_.reserve(slots);
  // Every type's table, whatever the type.
  for (size_t t = 0; t < types_.size(); ++t)
    if (tables_[t] && rows_of_type[t] > 0)
      tables_[t]->Reserve(tables_[t]->size() + rows_of_type[t] * copies);
  scripts_.reserve(scripts_.size() + scripts * copies);
  instances_.reserve(instances_.size() + copies);
  // Room for a name of its own per copy (a loader names each copy model#k).
  names_.Reserve(copies);
  if (prefault == nullptr) return;
  for (auto* v : {&X_PO_, &X_WO_}) prefault->AddSpare(*v);
  prefault->AddSpare(motions_);
  for (auto* v : {&motion_, &name_, &generation_, &row_}) prefault->AddSpare(*v);
  for (auto* v : {&parent_, &first_child_, &last_child_, &next_sibling_, &prev_sibling_, &instance_,
                  &script_})
    prefault->AddSpare(*v);
  for (auto* v : {&simulated_, &alive_, &model_root_}) prefault->AddSpare(*v);
  prefault->AddSpare(type_);
  for (size_t t = 0; t < types_.size(); ++t)
    if (tables_[t] && rows_of_type[t] > 0) {
      const auto [begin, bytes] = tables_[t]->Spare();
      prefault->Add(begin, bytes);
      prefault->AddSpare(tables_[t]->owners);
    }
  prefault->AddSpare(scripts_);
}

ObjectId Scene::DuplicateSubtree(ObjectId root, ObjectId new_parent, const Pose* X_PO) {
  const uint32_t root_slot = SlotOf(root);
  int32_t parent_slot = -1;
  if (!new_parent.IsNull()) parent_slot = static_cast<int32_t>(SlotOf(new_parent, "parent object"));
  std::vector<uint32_t> sources;
  CollectSubtree(root_slot, &sources);
  // The custom data blocks scripts wrote are charged again for the copy:
  // refused before anything is copied if the run cannot hold them.
  uint64_t charged = 0;
  const RunScriptMemory* run = nullptr;
  for (uint32_t src : custom_data_.empty() ? std::span<const uint32_t>{} : sources) {
    const auto data = custom_data_.find(src);
    if (data == custom_data_.end()) continue;
    for (const auto& [tag, block] : data->second) {
      if (block.writer == nullptr) continue;
      charged += CustomDataBytes(tag.size(), block.data.size());
      run = block.writer->run();
    }
  }
  if (run != nullptr && run->limit() > 0 && run->taken() + charged > run->limit())
    throw Error("copying '" + name_at(root_slot) + "': its custom data blocks (" +
                std::to_string(charged >> 20) + " MiB) would take the run's scripts past " +
                std::to_string(run->limit() >> 20) + " MiB (simulation.run_script_memory_mb)");
  // Pre-order guarantees a parent is copied before its children. The
  // copies sit by the sources' order.
  const SourceIndex index(sources);
  std::vector<uint32_t> copies(sources.size());
  for (size_t i = 0; i < sources.size(); ++i) {
    const uint32_t src = sources[i];
    const int32_t p = i == 0 ? parent_slot : static_cast<int32_t>(copies[index(parent_[src])]);
    const Pose pose = i == 0 && X_PO != nullptr ? *X_PO : X_PO_[src];
    copies[i] = CopyObject(src, p, pose);
  }
  // Remap internal references: a link inside the subtree points at the copy;
  // a link to an object outside stays as it was.
  if (!linked_dummy_.empty())
    for (size_t i = 0; i < sources.size(); ++i) {
      const auto linked = linked_dummy_.find(sources[i]);
      if (linked == linked_dummy_.end()) continue;
      const uint32_t link = linked->second;
      const int32_t inside = index(link);
      linked_dummy_[copies[i]] = inside >= 0 ? copies[inside] : link;
    }
  // The copies' world poses are in place: each was computed as it was made
  // (AllocateSlotNamed), parents first, from its parent's copy as it is now
  // (a joint's row is copied before its children are made).
  const uint32_t copy_root = copies[0];
  // A copy of a whole robot is a new robot.
  const int src_instance = instance_[root_slot];
  if (model_root_[root_slot] && src_instance >= 0 && instances_[src_instance].root == root &&
      instance_[copy_root] < 0) {
    const std::string model_name = instances_[src_instance].model_name;
    MakeModelInstance(IdAt(copy_root), model_name,
                      model_name + "#" + std::to_string(instances_.size()));
  }
  for (SceneListener* l : listeners_) l->OnSubtreeDuplicated(*this, sources, copies);
  return IdAt(copy_root);
}

std::vector<ObjectId> Scene::DuplicateSubtrees(ObjectId root, std::span<const Pose> X_WR,
                                               TaskScheduler& scheduler) {
  std::vector<ObjectId> roots;
  roots.reserve(X_WR.size());
  const uint32_t root_slot = SlotOf(root);
  std::vector<uint32_t> sources;
  CollectSubtree(root_slot, &sources);
  bool bulk = X_WR.size() > 1 && free_slots_.empty() && free_motions_.empty();
  for (size_t i = 0; bulk && i < sources.size(); ++i)
    bulk = !custom_data_.contains(sources[i]) && !linked_dummy_.contains(sources[i]);
  if (!bulk) {
    for (const Pose& X : X_WR) roots.push_back(DuplicateSubtree(root, {}, &X));
    return roots;
  }
  // Where each source's copy goes, as DuplicateSubtree would put it: the
  // copies' slots follow one another, copy after copy in the sources'
  // (pre-)order, and so do each table's rows, the motions and the scripts.
  const size_t k = sources.size(), n = X_WR.size();
  const SourceIndex index(sources);  // a source's relatives are sources
  struct Source {
    int32_t parent, first_child, last_child, next_sibling, prev_sibling;  // indices, -1 none
    uint32_t rank = 0;         // among the sources of its type with a table
    uint32_t motion = 0;       // among the sources with a motion
    int32_t script = -1;       // among the sources with a script attached
    bool serial_copy = false;  // a type whose copy rule runs on this thread
  };
  std::vector<Source> src(k);
  std::vector<uint32_t> rows_of_type(types_.size(), 0);
  uint32_t motions = 0, scripted = 0;
  for (size_t i = 0; i < k; ++i) {
    const uint32_t s = sources[i];
    Source& o = src[i];
    o.parent = i == 0 ? -1 : index(parent_[s]);
    o.first_child = index(first_child_[s]);
    o.last_child = index(last_child_[s]);
    o.next_sibling = i == 0 ? -1 : index(next_sibling_[s]);
    o.prev_sibling = i == 0 ? -1 : index(prev_sibling_[s]);
    const size_t t = static_cast<size_t>(type_[s]);
    if (tables_[t]) {
      o.rank = rows_of_type[t]++;
      o.serial_copy = types_[t]->copy_row != nullptr;
    }
    if (type_[s] == ObjectType::kShape) o.motion = motions++;
    if (script_[s] >= 0 && scripts_[script_[s]].source) o.script = static_cast<int32_t>(scripted++);
  }
  const uint32_t slot_base = slot_count();
  const size_t motion_base = motions_.size(), script_base = scripts_.size();
  std::vector<uint32_t> row_base(types_.size(), 0);
  for (size_t t = 0; t < types_.size(); ++t)
    if (tables_[t]) row_base[t] = static_cast<uint32_t>(tables_[t]->size());
  const int src_instance = instance_[root_slot];
  const bool robots =
      model_root_[root_slot] && src_instance >= 0 && instances_[src_instance].root == root;
  const int instance_base = static_cast<int>(instances_.size());
  // The arrays grow first (each on a thread: growing writes every new
  // element), then every copy is written on some thread.
  const size_t slots = slot_base + n * k;
  std::vector<std::function<void()>> grow = {
      [&] { X_PO_.resize(slots); }, [&] { X_WO_.resize(slots); },
      [&] {
        motion_.resize(slots);
        motions_.resize(motion_base + n * motions);
        for (auto* v : {&parent_, &first_child_, &last_child_, &next_sibling_, &prev_sibling_,
                        &instance_, &script_})
          v->resize(slots);
        type_.resize(slots);
        for (auto* v : {&row_, &generation_, &name_}) v->resize(slots);
        for (auto* v : {&simulated_, &alive_, &model_root_}) v->resize(slots);
        scripts_.resize(script_base + n * scripted);
      }};
  for (size_t t = 0; t < types_.size(); ++t)
    if (tables_[t] && rows_of_type[t] > 0)
      grow.push_back([&, t] { tables_[t]->Grow(n * rows_of_type[t]); });
  scheduler.ParallelFor(0, static_cast<int64_t>(grow.size()), 1, [&](int64_t b, int64_t e) {
    for (int64_t g = b; g < e; ++g) grow[static_cast<size_t>(g)]();
  });
  const auto copy_slot = [&](size_t c, int32_t i) -> int32_t {
    return i < 0 ? -1 : static_cast<int32_t>(slot_base + c * k + static_cast<size_t>(i));
  };
  scheduler.ParallelFor(0, static_cast<int64_t>(n), 64, [&](int64_t b, int64_t e) {
    // The copies' settings references, added once per task: the sources
    // hold theirs throughout, and rows without a copy rule are plain copies
    // into default rows (nothing released, nothing edited).
    const CountCopiesLocally count_locally;
    for (size_t c = static_cast<size_t>(b); c < static_cast<size_t>(e); ++c)
      for (size_t i = 0; i < k; ++i) {
        const uint32_t s = sources[i];
        const Source& o = src[i];
        const uint32_t slot = static_cast<uint32_t>(copy_slot(c, static_cast<int32_t>(i)));
        const size_t t = static_cast<size_t>(type_[s]);
        type_[slot] = type_[s];
        name_[slot] = name_[s];
        generation_[slot] = 0;
        alive_[slot] = 1;
        simulated_[slot] = 0;
        model_root_[slot] = model_root_[s];
        instance_[slot] = robots ? instance_base + static_cast<int>(c) : -1;
        parent_[slot] = copy_slot(c, o.parent);
        first_child_[slot] = copy_slot(c, o.first_child);
        last_child_[slot] = copy_slot(c, o.last_child);
        next_sibling_[slot] = copy_slot(c, o.next_sibling);
        prev_sibling_[slot] = copy_slot(c, o.prev_sibling);
        if (type_[s] == ObjectType::kShape) {
          const size_t m = motion_base + c * motions + o.motion;
          motion_[slot] = static_cast<uint32_t>(m);
          motions_[m] = motion_[s] != kNoMotion ? motions_[motion_[s]] : Motion{};
        } else {
          motion_[slot] = kNoMotion;
        }
        row_[slot] = 0;
        if (tables_[t]) {
          row_[slot] = row_base[t] + static_cast<uint32_t>(c * rows_of_type[t] + o.rank);
          if (!o.serial_copy) tables_[t]->CopyInto(row_[s], row_[slot], slot, nullptr);
        }
        script_[slot] = -1;
        if (o.script >= 0) {
          const size_t a = script_base + c * scripted + static_cast<size_t>(o.script);
          script_[slot] = static_cast<int32_t>(a);
          scripts_[a] = scripts_[script_[s]];
        }
        X_PO_[slot] = i == 0 ? X_WR[c] : X_PO_[s];
        // Parents first (pre-order), a joint's row before its children.
        X_WO_[slot] = o.parent < 0 ? X_PO_[slot]
                                   : ChildFrameAt(static_cast<uint32_t>(copy_slot(c, o.parent))) *
                                         X_PO_[slot];
      }
  });
  // On this thread, in DuplicateSubtree's order: the copy rules, the size
  // factors, the names' references, the robots, the listeners (told of
  // each copy in turn once the whole batch exists).
  for (size_t c = 0; c < n; ++c)
    for (size_t i = 0; i < k; ++i) {
      const uint32_t s = sources[i], slot = static_cast<uint32_t>(copy_slot(c, int32_t(i)));
      if (src[i].serial_copy) {
        const size_t t = static_cast<size_t>(type_[s]);
        tables_[t]->CopyInto(row_[s], row_[slot], slot, types_[t]->copy_row);
      }
      if (const auto f = size_factor_.find(s); f != size_factor_.end())
        size_factor_[slot] = f->second;
    }
  for (uint32_t s : sources) names_.Retain(name_[s], static_cast<uint32_t>(n));
  object_count_ += n * k;
  structure_version_ += n * k;
  order_dirty_ = true;
  std::vector<uint32_t> copies(k);
  for (size_t c = 0; c < n; ++c) {
    const uint32_t copy_root = static_cast<uint32_t>(copy_slot(c, 0));
    for (size_t i = 0; i < k; ++i) copies[i] = copy_root + static_cast<uint32_t>(i);
    if (robots) {
      const std::string& model_name = instances_[src_instance].model_name;
      instances_.push_back({model_name + "#" + std::to_string(instances_.size()), model_name,
                            IdAt(copy_root), true, copies});
    }
    for (SceneListener* l : listeners_) l->OnSubtreeDuplicated(*this, sources, copies);
    roots.push_back(IdAt(copy_root));
  }
  return roots;
}

// --- Size factor ---------------------------------------------------------------------

void Scene::ScaleSubtree(ObjectId root, double s) {
  const uint32_t root_slot = SlotOf(root);
  if (!std::isfinite(s) || !(s > 0))
    throw Error("cannot scale '" + name_at(root_slot) + "' by " + std::to_string(s) +
                ": the factor must be a finite number above 0");
  if (s == 1) return;
  std::vector<uint32_t> sub;
  CollectSubtree(root_slot, &sub);
  ScaleContext context;  // scaled assets (meshes), one per original within this call
  for (uint32_t slot : sub) {
    size_factor_[slot] = size_factor_at(slot) * s;
    if (slot != root_slot) X_PO_[slot].p = X_PO_[slot].p * s;
    const size_t type = static_cast<size_t>(type_[slot]);
    if (types_[type]->scale_row != nullptr)
      types_[type]->scale_row(*types_[type], tables_[type]->At(row_[slot]), s, &context);
  }
  RefreshSubtree(root_slot);
  ++structure_version_;
}

}  // namespace swarmsim
