// World snapshots: the bytes World::SaveState writes and World::RestoreState
// reads back (Python's World.snapshot()/restore()/pickling, `swarmsim run
// --save-state/--load-state`), and the writer and reader the state hooks of
// object types (ObjectTypeDescriptor::save_rows/load_rows) and modules
// (Module::SaveState/LoadState) use.
//
// What a snapshot holds, and what it refuses (the design, README.md
// "Snapshots"):
// - exactly what the world owns: time and step, the seed, every object's
//   poses and velocities, each type's changing rows (through its hooks: the
//   swarm devices' too, what range-and-bearing boards and IR transceivers
//   send and heard, light, LED and blob camera states and readings, ground
//   sensors, paint nozzles), custom data, the random streams, model
//   parameters set after load (World::WriteInstanceParameters), metric
//   samples not yet taken, and each module's own state (through its hooks:
//   the paint layer's painted pixels, covered_area's cells);
// - the dynamics engine is not serialised: Box2D and ODE keep contact caches
//   (warm starting) and broad-phase trees we cannot write out. Taking a
//   snapshot rebuilds the engine from the scene (as a hybrid switch does),
//   and restoring rebuilds it from the same scene, so the world a snapshot
//   was taken from and every world it is restored into continue identically.
//   Taking a snapshot therefore settles the contact caches: for box2d, ode
//   and planar (neighbour lists, its own headings) the snapshotted run
//   differs from one that never took one; kinematic keeps nothing.
// - refused with an Error naming why: Lua scripts (a robot's or the
//   world's), native controllers and plugin phase callbacks (their memory is
//   not ours), messages or signals in flight, a type whose rows change but
//   have no save hook (force sensors, paths, conveyors, mills, planning
//   tasks, collision and distance objects, rendering lights), a module with
//   no save hook (graphs, vision sensors, the video recorder).
// The bytes carry a fingerprint of the world (the world file's content, its
// settings, robot and object counts and names); restoring into another world,
// or corrupt or truncated bytes, is an Error and leaves the world as it was.
// Same machine architecture only (numbers are stored as they are in memory).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

namespace swarmsim {

// Appends values to a snapshot's bytes.
class StateWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    PutBytes(&value, sizeof(T));
  }
  void PutBytes(const void* data, size_t size) {
    bytes_.append(static_cast<const char*>(data), size);
  }
  void PutString(std::string_view text) {
    Put<uint64_t>(text.size());
    bytes_.append(text);
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Reads them back in the same order. Every read past the end, and every
// value out of its range, throws swarmsim::Error ("snapshot: ...").
class StateReader {
 public:
  explicit StateReader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T> && !std::is_same_v<T, bool>);
    T value;
    GetBytes(&value, sizeof(T));
    return value;
  }
  bool GetBool();  // one byte, 0 or 1
  void GetBytes(void* out, size_t size);
  // A count of items of `item_size` bytes each that the rest could hold.
  uint64_t GetCount(size_t item_size);
  std::string GetString();
  // Throws unless `value == expected` ("snapshot: <what> is <value>, this world has <expected>").
  void Expect(uint64_t value, uint64_t expected, std::string_view what) const;
  size_t remaining() const { return bytes_.size() - offset_; }
  [[noreturn]] void Fail(const std::string& message) const;

 private:
  std::string_view bytes_;
  size_t offset_ = 0;
};

}  // namespace swarmsim
