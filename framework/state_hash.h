// A 64-bit hash of everything that changes a world's future (xxHash XXH3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace swarmsim {

class StateHasher {
 public:
  StateHasher();
  ~StateHasher();
  StateHasher(const StateHasher&) = delete;
  StateHasher& operator=(const StateHasher&) = delete;

  // Small values are gathered and handed to XXH3 a few KiB at a time (a
  // large world adds millions of them); XXH3's streaming digest does not
  // depend on how the input is split, so the hash is that of the bytes in
  // order, as if each were added alone.
  void Add(const void* data, size_t bytes);
  template <typename T>
  void AddValue(const T& value) {
    static_assert(sizeof(T) <= kBuffer);
    if (used_ + sizeof(T) <= kBuffer) {
      std::memcpy(buffer_ + used_, &value, sizeof(T));
      used_ += sizeof(T);
      return;
    }
    Add(&value, sizeof(T));
  }
  uint64_t Digest() const;

  static std::string ToHex(uint64_t hash);  // 16 lowercase hex digits

 private:
  static constexpr size_t kBuffer = 4096;
  void Flush() const;

  void* state_;  // XXH3_state_t, kept out of the header
  mutable size_t used_ = 0;
  mutable unsigned char buffer_[kBuffer];
};

}  // namespace swarmsim
