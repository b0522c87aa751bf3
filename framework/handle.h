// Typed handles to scene objects, after Box2D's b2BodyId: a 1-based slot
// index and a generation. Zero is null. A handle whose slot was freed (and
// perhaps reused) has a stale generation and is rejected by every API entry.
#pragma once

#include <compare>
#include <cstdint>

namespace swarmsim {

struct ObjectId {           // 8 bytes
  uint32_t index1 = 0;      // slot + 1; 0 means null
  uint32_t generation = 0;  // bumped each time the slot is freed

  constexpr bool IsNull() const { return index1 == 0; }
  constexpr uint32_t index() const { return index1 - 1; }
  constexpr bool operator==(const ObjectId&) const = default;
  constexpr auto operator<=>(const ObjectId&) const = default;

  // Lua sees one integer: generation in the high 32 bits, index1 in the low.
  // First-generation handles are therefore small integers (1, 2, 3, ...).
  constexpr int64_t ToInteger() const {
    return static_cast<int64_t>((static_cast<uint64_t>(generation) << 32) | index1);
  }
  static constexpr ObjectId FromInteger(int64_t value) {
    const auto u = static_cast<uint64_t>(value);
    return {static_cast<uint32_t>(u & 0xffffffffu), static_cast<uint32_t>(u >> 32)};
  }
};

}  // namespace swarmsim
