// Object names, each distinct string stored once (Scene's names): the
// 10,000 copies of a robot share "leftMotor", "prox", ... A name costs its
// object 4 bytes instead of a std::string's 32.
//
// Not thread-safe to change; reading (operator[]) is safe while nothing
// changes (the scene's objects are added, renamed and removed between phases).
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace swarmsim {

class NamePool {
 public:
  // The id of `name`, with one more reference.
  uint32_t Intern(std::string_view name) {
    if (auto it = ids_.find(name); it != ids_.end()) {
      ++refs_[it->second];
      return it->second;
    }
    uint32_t id;
    if (!free_.empty()) {
      id = free_.back();
      free_.pop_back();
      strings_[id] = name;
      refs_[id] = 1;
    } else {
      id = static_cast<uint32_t>(strings_.size());
      strings_.emplace_back(name);
      refs_.push_back(1);
    }
    ids_.emplace(strings_[id], id);  // a view of the stored string (a deque's stay put)
    return id;
  }
  // The id of `name` if some object is named so, else kNone (nothing interned).
  static constexpr uint32_t kNone = UINT32_MAX;
  uint32_t Find(std::string_view name) const {
    const auto it = ids_.find(name);
    return it == ids_.end() ? kNone : it->second;
  }
  // Whether the name `id` is `name` (an id remembered from an earlier Find
  // still names it).
  bool Holds(uint32_t id, std::string_view name) const {
    return id < strings_.size() && refs_[id] > 0 && strings_[id] == name;
  }
  // `times` more references to the name `id` (copies of an object).
  void Retain(uint32_t id, uint32_t times = 1) { refs_[id] += times; }
  // Room for `more` distinct names without rehashing (a loader about to
  // name a million copies model#k).
  void Reserve(size_t more) { ids_.reserve(ids_.size() + more); }
  // One fewer; the string goes with its last reference.
  void Release(uint32_t id) {
    if (--refs_[id] > 0) return;
    ids_.erase(strings_[id]);
    strings_[id].clear();
    strings_[id].shrink_to_fit();
    free_.push_back(id);
  }
  const std::string& operator[](uint32_t id) const { return strings_[id]; }
  // Distinct names held.
  size_t size() const { return ids_.size(); }

 private:
  std::deque<std::string> strings_;  // by id
  std::vector<uint32_t> refs_;       // by id: objects named so
  std::vector<uint32_t> free_;       // ids of released names, to reuse
  std::unordered_map<std::string_view, uint32_t> ids_;
};

}  // namespace swarmsim
