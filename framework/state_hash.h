// A 64-bit hash of everything that changes a world's future (xxHash XXH3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace swarmsim {

class StateHasher {
 public:
  StateHasher();
  ~StateHasher();
  StateHasher(const StateHasher&) = delete;
  StateHasher& operator=(const StateHasher&) = delete;

  void Add(const void* data, size_t bytes);
  template <typename T>
  void AddValue(const T& value) {
    Add(&value, sizeof(T));
  }
  uint64_t Digest() const;

  static std::string ToHex(uint64_t hash);  // 16 lowercase hex digits

 private:
  void* state_;  // XXH3_state_t, kept out of the header
};

}  // namespace swarmsim
