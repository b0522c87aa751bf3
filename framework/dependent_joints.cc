#include "framework/dependent_joints.h"

#include <algorithm>
#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"

namespace swarmsim {
namespace {

const JointDependency* DependencyAt(const Scene& scene, uint32_t slot) {
  return scene.joints()[scene.row_at(slot)].depends();
}

// Whether the master of the dependent joint at `slot`, and its masters in
// turn, are still there (the load checked them: one that is not was in a
// robot removed since).
bool MastersThere(const Scene& scene, uint32_t slot, size_t joints) {
  for (size_t depth = 0; DependencyAt(scene, slot) != nullptr && depth <= joints; ++depth) {
    const ObjectId master = scene.FindObject(DependencyAt(scene, slot)->master, scene.IdAt(slot));
    if (master.IsNull() || scene.type(master) != ObjectType::kJoint) return false;
    slot = master.index();
  }
  return true;
}

}  // namespace

uint32_t JointMasterSlot(const Scene& scene, uint32_t slot) {
  const JointDependency& d = *DependencyAt(scene, slot);
  const ObjectId self = scene.IdAt(slot);
  const ObjectId master = scene.FindObject(d.master, self);
  if (master.IsNull())
    throw Error(d.where + ": joint '" + scene.PathOf(self) + "': master '" + d.master +
                "' matches no object" + scene.ExplainMissingPath(d.master, self));
  if (scene.type(master) != ObjectType::kJoint)
    throw Error(d.where + ": joint '" + scene.PathOf(self) + "': master '" + d.master + "' is a " +
                scene.type_descriptor(scene.type(master)).name + ", not a joint");
  if (master == self)
    throw Error(d.where + ": joint '" + scene.PathOf(self) + "' cannot depend on itself");
  return master.index();
}

void CheckJointDependency(const Scene& scene, ObjectId id) {
  const uint32_t start = id.index();
  if (DependencyAt(scene, start) == nullptr) return;
  std::vector<uint32_t> chain = {start};
  uint32_t s = start;
  while (DependencyAt(scene, s) != nullptr) {
    s = JointMasterSlot(scene, s);
    const auto seen = std::find(chain.begin(), chain.end(), s);
    if (seen == chain.end()) {
      chain.push_back(s);
      continue;
    }
    if (seen != chain.begin()) return;  // a cycle further on: its own joints report it
    std::string names;
    for (uint32_t c : chain) {
      names += '\'';
      names += scene.PathOf(scene.IdAt(c));
      names += "' -> ";
    }
    names += '\'';
    names += scene.PathOf(id);
    names += '\'';
    throw Error(DependencyAt(scene, start)->where + ": dependent joints form a cycle: " + names +
                " (a joint cannot follow itself through its masters)");
  }
}

void DependentJoints::Refresh(const Scene& scene) {
  const bool first = version_ == ~uint64_t{0};
  version_ = scene.structure_version();
  links_.clear();
  // Each dependent joint with its depth (masters above it); by depth, then row.
  struct Entry {
    uint32_t depth, row, master_row;
  };
  std::vector<Entry> entries;
  const auto owners = scene.joint_owners();
  for (uint32_t row = 0; row < owners.size(); ++row) {
    const uint32_t slot = owners[row];
    if (!scene.alive_at(slot) || scene.joints()[row].depends() == nullptr) continue;
    // A master removed at run time (its robot was): the joint keeps where
    // it is, following nothing. (The first time, a missing master is an
    // error below: the world was built so.)
    if (!first && !MastersThere(scene, slot, owners.size())) continue;
    uint32_t depth = 0;
    for (uint32_t s = slot; DependencyAt(scene, s) != nullptr && depth <= owners.size(); ++depth)
      s = JointMasterSlot(scene, s);
    if (depth > owners.size()) CheckJointDependency(scene, scene.IdAt(slot));  // throws
    entries.push_back({depth, row, scene.row_at(JointMasterSlot(scene, slot))});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.depth != b.depth ? a.depth < b.depth : a.row < b.row;
  });
  for (const Entry& e : entries) links_.push_back({e.row, e.master_row});
}

bool DependentJoints::Apply(Scene* scene, bool targets) {
  if (version_ != scene->structure_version()) Refresh(*scene);
  auto joints = scene->joints();
  for (const Link& l : links_) {
    JointData& j = joints[l.row];
    const JointData& m = joints[l.master_row];
    const JointDependency& d = *j.depends();
    const double q = d.offset + d.factor * m.position;
    if (j.simulated) {
      if (targets) j.target_position = q;
      continue;
    }
    j.position = q;
    j.velocity = d.factor * m.velocity;
  }
  return !links_.empty();
}

}  // namespace swarmsim
