#include "framework/scene.h"

#include <algorithm>
#include <atomic>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/script_memory.h"
#include "framework/state_hash.h"

namespace swarmsim {

const char* ToString(ObjectType type) {
  const auto core = CoreObjectTypes();
  const size_t t = static_cast<size_t>(type);
  return t < core.size() ? core[t]->name : "registered type";
}

const char* ToString(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kBox: return "box";
    case ShapeKind::kCylinder: return "cylinder";
    case ShapeKind::kSphere: return "sphere";
    case ShapeKind::kCapsule: return "capsule";
    case ShapeKind::kMesh: return "mesh";
  }
  return "?";
}

const char* ToString(JointType type) {
  switch (type) {
    case JointType::kRevolute: return "revolute";
    case JointType::kPrismatic: return "prismatic";
    case JointType::kSpherical: return "spherical";
    case JointType::kFixed: return "fixed";
    case JointType::kScrew: return "screw";
  }
  return "?";
}

const char* ToString(JointMode mode) {
  switch (mode) {
    case JointMode::kPassive: return "passive";
    case JointMode::kVelocity: return "velocity";
    case JointMode::kPosition: return "position";
    case JointMode::kForce: return "force";
  }
  return "?";
}

double ShapeData::BoundingRadius() const {
  switch (kind) {
    case ShapeKind::kBox: return 0.5 * std::sqrt(size.x * size.x + size.y * size.y);
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
    case ShapeKind::kSphere: return size.x;
    case ShapeKind::kMesh:
      return mesh ? mesh->footprint_radius() : 0.5 * std::hypot(size.x, size.y);
  }
  return 0;
}

Pose JointData::Motion() const {
  switch (settings->type) {
    case JointType::kRevolute: return {{}, Quat::FromAxisAngle({0, 0, 1}, position)};
    case JointType::kPrismatic: return {{0, 0, position}, {}};
    case JointType::kSpherical: return {{}, ball};
    case JointType::kScrew:
      return {{0, 0, settings->pitch * position}, Quat::FromAxisAngle({0, 0, 1}, position)};
    case JointType::kFixed: break;
  }
  return {};
}

void JointData::JumpTo(double q) {
  position = q;
  velocity = 0;
  if (settings->mode == JointMode::kPosition) target_position = q;
}

Scene::Scene() {
  static std::atomic<uint64_t> scenes{0};
  serial_ = ++scenes;
  for (const ObjectTypeDescriptor* type : CoreObjectTypes()) RegisterType(*type);
}
Scene::~Scene() = default;

// --- Object types ----------------------------------------------------------------

ObjectType Scene::RegisterType(const ObjectTypeDescriptor& type) {
  ObjectType existing;
  if (FindType(type.name, &existing))
    throw Error("object type '" + std::string(type.name) + "' is registered twice");
  if (types_.size() >= static_cast<size_t>(kMaxObjectTypes))
    throw Error("cannot register object type '" + std::string(type.name) + "': at most " +
                std::to_string(kMaxObjectTypes) + " object types");
  types_.push_back(&type);
  type_names_.push_back(type.name);
  tables_.push_back(type.make_rows != nullptr ? type.make_rows(type) : nullptr);
  listing_order_.clear();
  for (const size_t t : ListingOrder(types_)) listing_order_.push_back(static_cast<ObjectType>(t));
  return static_cast<ObjectType>(types_.size() - 1);
}

bool Scene::FindType(std::string_view name, ObjectType* type) const {
  for (size_t t = 0; t < types_.size(); ++t) {
    if (name != types_[t]->name) continue;
    *type = static_cast<ObjectType>(t);
    return true;
  }
  return false;
}

// --- Slots ----------------------------------------------------------------------

uint32_t Scene::AllocateSlot(std::string_view name, ObjectId parent, const Pose& X_PO,
                             ObjectType type) {
  int32_t parent_slot = -1;
  if (!parent.IsNull()) parent_slot = static_cast<int32_t>(SlotOf(parent, "parent object"));
  return AllocateSlotNamed(names_.Intern(name), parent_slot, X_PO, type);
}

uint32_t Scene::AllocateSlotNamed(uint32_t name, int32_t parent_slot, const Pose& X_PO,
                                  ObjectType type) {
  uint32_t slot;
  if (!free_slots_.empty()) {
    // Reuse the lowest free slot so that slot order stays deterministic.
    auto it = std::min_element(free_slots_.begin(), free_slots_.end());
    slot = *it;
    free_slots_.erase(it);
  } else {
    slot = static_cast<uint32_t>(generation_.size());
    X_PO_.emplace_back();
    X_WO_.emplace_back();
    motion_.push_back(kNoMotion);
    parent_.push_back(-1);
    first_child_.push_back(-1);
    last_child_.push_back(-1);
    next_sibling_.push_back(-1);
    prev_sibling_.push_back(-1);
    type_.push_back(type);
    row_.push_back(0);
    instance_.push_back(-1);
    simulated_.push_back(0);
    generation_.push_back(0);
    alive_.push_back(0);
    model_root_.push_back(0);
    name_.push_back(0);
    script_.push_back(-1);
  }
  X_PO_[slot] = X_PO;
  if (type == ObjectType::kShape) {
    if (!free_motions_.empty()) {
      motion_[slot] = free_motions_.back();
      free_motions_.pop_back();
      motions_[motion_[slot]] = {};
    } else {
      motion_[slot] = static_cast<uint32_t>(motions_.size());
      motions_.emplace_back();
    }
  }
  type_[slot] = type;
  row_[slot] = 0;
  simulated_[slot] = 0;
  alive_[slot] = 1;
  model_root_[slot] = 0;
  name_[slot] = name;
  script_[slot] = -1;
  parent_[slot] = -1;
  first_child_[slot] = last_child_[slot] = next_sibling_[slot] = prev_sibling_[slot] = -1;
  instance_[slot] = parent_slot >= 0 ? instance_[parent_slot] : -1;
  if (parent_slot >= 0) LinkChild(static_cast<uint32_t>(parent_slot), slot);
  X_WO_[slot] = parent_slot >= 0 ? ChildFrameAt(static_cast<uint32_t>(parent_slot)) * X_PO : X_PO;
  if (instance_[slot] >= 0) RebuildInstanceObjects(instance_[slot]);
  ++object_count_;
  ++structure_version_;
  order_dirty_ = true;
  return slot;
}

void Scene::FreeSlot(uint32_t slot) {
  if (RowTable* table = tables_[static_cast<size_t>(type_[slot])].get()) {
    const uint32_t moved = table->SwapRemove(row_[slot]);
    if (moved != RowTable::kNoOwner) row_[moved] = row_[slot];
  }
  if (script_[slot] >= 0) scripts_[script_[slot]] = {};
  // Unlink any dummy linked to this one.
  if (const auto link = linked_dummy_.find(slot); link != linked_dummy_.end()) {
    if (const auto back = linked_dummy_.find(link->second);
        back != linked_dummy_.end() && back->second == slot)
      linked_dummy_.erase(back);
    linked_dummy_.erase(link);
  }
  size_factor_.erase(slot);
  alive_[slot] = 0;
  if (motion_[slot] != kNoMotion) {
    free_motions_.push_back(motion_[slot]);
    motion_[slot] = kNoMotion;
  }
  DropCustomData(slot);
  ++generation_[slot];
  names_.Release(name_[slot]);
  free_slots_.push_back(slot);
  --object_count_;
}

ObjectId Scene::AddObject(ObjectType type, std::string name, ObjectId parent, const Pose& X_PO,
                          const void* row) {
  SWARMSIM_CHECK(static_cast<size_t>(type) < types_.size(), "unregistered object type");
  const uint32_t slot = AllocateSlot(std::move(name), parent, X_PO, type);
  if (RowTable* table = tables_[static_cast<size_t>(type)].get())
    row_[slot] = table->Append(row, slot);
  return IdAt(slot);
}

ObjectId Scene::AddDummy(std::string name, ObjectId parent, const Pose& X_PO) {
  return AddObject(ObjectType::kDummy, std::move(name), parent, X_PO, nullptr);
}
ObjectId Scene::AddShape(std::string name, ObjectId parent, const Pose& X_PO,
                         const ShapeData& shape) {
  const Shared<ShapeData> row(shape);
  return AddObject(ObjectType::kShape, std::move(name), parent, X_PO, &row);
}
ObjectId Scene::AddJoint(std::string name, ObjectId parent, const Pose& X_PO,
                         const JointData& joint) {
  return AddObject(ObjectType::kJoint, std::move(name), parent, X_PO, &joint);
}

void* Scene::row_data(ObjectId id) {
  const uint32_t slot = SlotOf(id);
  RowTable* table = tables_[static_cast<size_t>(type_[slot])].get();
  return table != nullptr ? table->At(row_[slot]) : nullptr;
}

// --- Tree links -------------------------------------------------------------------

void Scene::LinkChild(uint32_t parent, uint32_t child) {
  parent_[child] = static_cast<int32_t>(parent);
  prev_sibling_[child] = last_child_[parent];
  next_sibling_[child] = -1;
  if (last_child_[parent] >= 0)
    next_sibling_[last_child_[parent]] = static_cast<int32_t>(child);
  else
    first_child_[parent] = static_cast<int32_t>(child);
  last_child_[parent] = static_cast<int32_t>(child);
}

void Scene::UnlinkChild(uint32_t child) {
  const int32_t parent = parent_[child];
  if (parent < 0) return;
  if (prev_sibling_[child] >= 0)
    next_sibling_[prev_sibling_[child]] = next_sibling_[child];
  else
    first_child_[parent] = next_sibling_[child];
  if (next_sibling_[child] >= 0)
    prev_sibling_[next_sibling_[child]] = prev_sibling_[child];
  else
    last_child_[parent] = prev_sibling_[child];
  parent_[child] = -1;
  prev_sibling_[child] = next_sibling_[child] = -1;
}

void Scene::CollectSubtree(uint32_t slot, std::vector<uint32_t>* out) const {
  // Iterative DFS pre-order, children in insertion order. (The stack is
  // the thread's own: a loader copying a million robots collects a subtree
  // per copy.)
  thread_local std::vector<uint32_t> stack;
  stack.assign(1, slot);
  while (!stack.empty()) {
    const uint32_t s = stack.back();
    stack.pop_back();
    out->push_back(s);
    const size_t mark = stack.size();
    for (int32_t c = first_child_[s]; c >= 0; c = next_sibling_[c]) stack.push_back(c);
    std::reverse(stack.begin() + static_cast<std::ptrdiff_t>(mark), stack.end());
  }
}

void Scene::RemoveSubtree(ObjectId root) {
  const uint32_t slot = SlotOf(root);
  std::vector<uint32_t> doomed;
  CollectSubtree(slot, &doomed);
  UnlinkChild(slot);
  for (uint32_t s : doomed) {
    if (model_root_[s] && instance_[s] >= 0 && instances_[instance_[s]].root == IdAt(s)) {
      instances_[instance_[s]].alive = false;
      instances_[instance_[s]].objects.clear();
    }
  }
  for (SceneListener* l : listeners_) l->OnSubtreeRemoved(*this, doomed);
  const int inst = instance_[slot];
  for (uint32_t s : doomed) FreeSlot(s);
  if (inst >= 0 && instances_[inst].alive) RebuildInstanceObjects(inst);
  ++structure_version_;
  order_dirty_ = true;
}

void Scene::SetParent(ObjectId id, ObjectId new_parent, bool keep_world_pose) {
  const uint32_t slot = SlotOf(id);
  int32_t parent_slot = -1;
  if (!new_parent.IsNull()) {
    parent_slot = static_cast<int32_t>(SlotOf(new_parent, "parent object"));
    for (int32_t a = parent_slot; a >= 0; a = parent_[a])
      if (a == static_cast<int32_t>(slot))
        throw Error("cannot make '" + name_at(slot) + "' a child of its own descendant '" +
                    name_at(parent_slot) + "'");
  }
  const Pose X_WO = X_WO_[slot];
  UnlinkChild(slot);
  if (parent_slot >= 0) LinkChild(static_cast<uint32_t>(parent_slot), slot);
  if (keep_world_pose) {
    X_PO_[slot] = parent_slot >= 0 ? ChildFrameAt(parent_slot).Inverse() * X_WO : X_WO;
  }
  ++structure_version_;
  order_dirty_ = true;
  RefreshSubtree(slot);
}

ObjectId Scene::parent(ObjectId id) const {
  const int32_t p = parent_[SlotOf(id)];
  return p >= 0 ? IdAt(static_cast<uint32_t>(p)) : ObjectId{};
}

std::vector<ObjectId> Scene::children(ObjectId id) const {
  std::vector<ObjectId> out;
  for (int32_t c = first_child_[SlotOf(id)]; c >= 0; c = next_sibling_[c])
    out.push_back(IdAt(static_cast<uint32_t>(c)));
  return out;
}

void Scene::set_name(ObjectId id, std::string name) {
  const uint32_t slot = SlotOf(id);
  const uint32_t old = name_[slot];
  name_[slot] = names_.Intern(name);
  names_.Release(old);
  ++renames_;
}

// --- Validity -----------------------------------------------------------------------

uint32_t Scene::SlotOf(ObjectId id, std::string_view what) const {
  if (IsValid(id)) return id.index();
  std::string msg(what);
  if (id.IsNull()) throw Error(msg + " handle is null");
  if (id.index() >= generation_.size())
    throw Error(msg + " handle " + std::to_string(id.ToInteger()) + " does not exist");
  throw Error(msg + " handle " + std::to_string(id.ToInteger()) +
              " is stale: the object was removed");
}

// --- Poses ---------------------------------------------------------------------------

Pose Scene::ChildFrameAt(uint32_t slot) const {
  if (type_[slot] == ObjectType::kJoint) return X_WO_[slot] * joints()[row_[slot]].Motion();
  return X_WO_[slot];
}

void Scene::RefreshSubtree(uint32_t slot) {
  std::vector<uint32_t> sub;
  CollectSubtree(slot, &sub);
  for (uint32_t s : sub) {
    const int32_t p = parent_[s];
    X_WO_[s] = p >= 0 ? ChildFrameAt(static_cast<uint32_t>(p)) * X_PO_[s] : X_PO_[s];
  }
}

void Scene::SetLocalPose(ObjectId id, const Pose& X_PO) {
  const uint32_t slot = SlotOf(id);
  X_PO_[slot] = X_PO;
  RefreshSubtree(slot);
}

void Scene::SetWorldPose(ObjectId id, const Pose& X_WO) {
  const uint32_t slot = SlotOf(id);
  const int32_t p = parent_[slot];
  X_PO_[slot] = p >= 0 ? ChildFrameAt(static_cast<uint32_t>(p)).Inverse() * X_WO : X_WO;
  RefreshSubtree(slot);
}

void Scene::RebuildOrder() const {
  order_.clear();
  order_.reserve(object_count_);
  for (uint32_t s = 0; s < generation_.size(); ++s)
    if (alive_[s] && parent_[s] < 0) CollectSubtree(s, &order_);
  scene_order_.clear();
  instances_independent_ = true;
  for (uint32_t s : order_) {
    const int32_t p = parent_[s];
    if (instance_[s] < 0) {
      scene_order_.push_back(s);
      if (p >= 0 && instance_[p] >= 0) instances_independent_ = false;  // hangs from a robot
    } else if (p >= 0 && instance_[p] != instance_[s]) {
      instances_independent_ = false;  // a robot mounted on something else
    }
  }
  order_dirty_ = false;
}

bool Scene::InstancesAreIndependent() const {
  if (order_dirty_) RebuildOrder();
  return instances_independent_;
}

void Scene::UpdatePoses(std::span<const uint32_t> slots) {
  // Raw pointers: no bounds or handle checks in the loop (every slot in an
  // order list is alive, its parent too).
  const int32_t* const parent = parent_.data();
  const ObjectType* const type = type_.data();
  const uint32_t* const row = row_.data();
  const JointData* const joint_rows = joints().data();
  uint8_t* const simulated = simulated_.data();
  Pose* const X_PO = X_PO_.data();
  Pose* const X_WO = X_WO_.data();
  // X_WF: the frame children of `frame_slot` hang from (ChildFrameAt), kept
  // across siblings. The 24 sensors of a ring under one body read it once,
  // and a joint's motion (its sin/cos) is computed once for all its
  // children. It is dropped when `frame_slot` itself is updated, so it is
  // always what ChildFrameAt would return at that point.
  int32_t frame_slot = -1;
  Pose X_WF;
  for (const uint32_t s : slots) {
    const int32_t p = parent[s];
    if (p >= 0 && p != frame_slot) {
      X_WF = type[p] == ObjectType::kJoint ? X_WO[p] * joint_rows[row[p]].Motion() : X_WO[p];
      frame_slot = p;
    }
    if (simulated[s]) {
      // The backend owns X_WO; derive the local pose from it.
      X_PO[s] = p >= 0 ? X_WF.Inverse() * X_WO[s] : X_WO[s];
      simulated[s] = 0;
    } else {
      X_WO[s] = p >= 0 ? X_WF * X_PO[s] : X_PO[s];
    }
    if (static_cast<int32_t>(s) == frame_slot) frame_slot = -1;
  }
}

void Scene::UpdateSceneObjectPoses() {
  if (order_dirty_) RebuildOrder();
  UpdatePoses(scene_order_);
}

void Scene::UpdateWorldPoses() {
  if (order_dirty_) RebuildOrder();
  UpdatePoses(order_);
}

void Scene::UpdateWorldPoses(int instance) {
  // The root's parent (if any) is outside the instance and is up to date.
  UpdatePoses(instances_.at(instance).objects);
}

// --- Typed data ----------------------------------------------------------------------------

// "a shape", "an ir_transceiver".
static std::string WithArticle(std::string_view type_name) {
  const bool vowel =
      !type_name.empty() && std::string_view("aeiou").find(type_name[0]) != std::string_view::npos;
  return (vowel ? "an " : "a ") + std::string(type_name);
}

static void ExpectType(const Scene& scene, uint32_t slot, ObjectType want) {
  if (scene.type_at(slot) != want)
    throw Error("object '" + scene.name_at(slot) + "' is " +
                WithArticle(scene.type_name(scene.type_at(slot))) + ", not " +
                WithArticle(scene.type_name(want)));
}

const ShapeData& Scene::shape(ObjectId id) const {
  const uint32_t s = SlotOf(id, "shape");
  ExpectType(*this, s, ObjectType::kShape);
  return shapes()[row_[s]];
}
ShapeData& Scene::mutable_shape(ObjectId id) {
  const uint32_t s = SlotOf(id, "shape");
  ExpectType(*this, s, ObjectType::kShape);
  return Table<Shared<ShapeData>>(ObjectType::kShape).rows[row_[s]].Edit();
}
void Scene::SetShapeDynamic(ObjectId id, bool dynamic) {
  ShapeData& shape = mutable_shape(id);
  if (shape.dynamic == dynamic) return;
  shape.dynamic = dynamic;
  ++structure_version_;
}
void Scene::SetSurfaceVelocity(ObjectId id, const Vec3& v_S, const Vec3& w_S) {
  ShapeData& shape = mutable_shape(id);
  const bool was_moving = shape.HasMovingSurface();
  shape.surface_velocity = v_S;
  shape.surface_angular_velocity = w_S;
  if (!was_moving && shape.HasMovingSurface()) ++structure_version_;
}
const JointData& Scene::joint(ObjectId id) const {
  const uint32_t s = SlotOf(id, "joint");
  ExpectType(*this, s, ObjectType::kJoint);
  return joints()[row_[s]];
}
JointData& Scene::mutable_joint(ObjectId id) {
  const uint32_t s = SlotOf(id, "joint");
  ExpectType(*this, s, ObjectType::kJoint);
  return joints()[row_[s]];
}
uint32_t Scene::SlotOfType(ObjectId id, ObjectType type, std::string_view what) const {
  const uint32_t s = SlotOf(id, what);
  ExpectType(*this, s, type);
  return s;
}

void Scene::LinkDummies(ObjectId a, ObjectId b) {
  const uint32_t sa = SlotOf(a, "dummy"), sb = SlotOf(b, "dummy");
  ExpectType(*this, sa, ObjectType::kDummy);
  ExpectType(*this, sb, ObjectType::kDummy);
  linked_dummy_[sa] = sb;
  linked_dummy_[sb] = sa;
}

void Scene::WriteCustomData(ObjectId id, const std::string& tag, std::string data,
                            ScriptMemory* writer) {
  const uint32_t slot = SlotOf(id);
  auto found = custom_data_.find(slot);
  if (found != custom_data_.end()) {
    CustomData& blocks = found->second;
    if (auto it = blocks.find(tag); it != blocks.end()) {
      if (it->second.writer != nullptr)
        it->second.writer->Release(CustomDataBytes(tag.size(), it->second.data.size()));
      if (data.empty()) blocks.erase(it);
    }
    if (blocks.empty()) custom_data_.erase(found);
  }
  if (data.empty()) {
    if (writer != nullptr) writer->Release(CustomDataBytes(tag.size(), 0));
    return;
  }
  custom_data_[slot][tag] = {std::move(data), writer};
}

void Scene::DropCustomData(uint32_t slot) {
  const auto found = custom_data_.find(slot);
  if (found == custom_data_.end()) return;
  const CustomData blocks = std::move(found->second);
  custom_data_.erase(found);
  for (const auto& [tag, block] : blocks)
    if (block.writer != nullptr)
      block.writer->Release(CustomDataBytes(tag.size(), block.data.size()));
}

const std::string* Scene::ReadCustomData(ObjectId id, const std::string& tag) const {
  const auto found = custom_data_.find(SlotOf(id));
  if (found == custom_data_.end()) return nullptr;
  auto it = found->second.find(tag);
  return it == found->second.end() ? nullptr : &it->second.data;
}

void Scene::HashCustomData(uint32_t slot, StateHasher* hasher) const {
  const auto found = custom_data_.find(slot);
  if (found == custom_data_.end()) return;
  hasher->AddValue(slot);
  for (const auto& [tag, block] : found->second) {
    hasher->AddValue(tag.size());
    hasher->Add(tag.data(), tag.size());
    hasher->AddValue(block.data.size());
    hasher->Add(block.data.data(), block.data.size());
  }
}

ObjectId Scene::linked_dummy(ObjectId id) const {
  const auto it = linked_dummy_.find(SlotOf(id, "dummy"));
  return it != linked_dummy_.end() ? IdAt(it->second) : ObjectId{};
}

// --- Scripts ------------------------------------------------------------------------------

void Scene::AttachScript(ObjectId id, std::shared_ptr<const ScriptSource> source,
                         bool explicit_handling) {
  const uint32_t slot = SlotOf(id);
  if (script_[slot] < 0) {
    script_[slot] = static_cast<int32_t>(scripts_.size());
    scripts_.emplace_back();
  }
  scripts_[script_[slot]] = {std::move(source), true, explicit_handling};
}

const ScriptAttachment* Scene::script(ObjectId id) const { return script_at(SlotOf(id)); }

const ScriptAttachment* Scene::script_at(uint32_t slot) const {
  const int32_t i = script_[slot];
  return i >= 0 && scripts_[i].source ? &scripts_[i] : nullptr;
}

// --- Models -------------------------------------------------------------------------------

void Scene::RebuildInstanceObjects(int instance) {
  ModelInstance& inst = instances_[instance];
  inst.objects.clear();
  CollectSubtree(inst.root.index(), &inst.objects);
}

int Scene::MakeModelInstance(ObjectId root, std::string model_name, std::string instance_name) {
  const uint32_t slot = SlotOf(root, "model root");
  model_root_[slot] = 1;
  for (int32_t a = parent_[slot]; a >= 0; a = parent_[a])
    if (model_root_[a]) return instance_[a];  // nested model: part of its ancestor's instance
  const int index = static_cast<int>(instances_.size());
  instances_.push_back({std::move(instance_name), std::move(model_name), root, true, {}});
  RebuildInstanceObjects(index);
  for (uint32_t s : instances_[index].objects) instance_[s] = index;
  return index;
}

}  // namespace swarmsim
