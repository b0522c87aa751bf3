#include "framework/state_hash.h"

#include <xxhash.h>

#include <cstdio>
#include <new>

namespace swarmsim {

StateHasher::StateHasher() : state_(XXH3_createState()) {
  // xxHash returns null when malloc does (out of memory): a hash then
  // crashed in XXH3_64bits_update.
  if (state_ == nullptr) throw std::bad_alloc();
  XXH3_64bits_reset(static_cast<XXH3_state_t*>(state_));
}

StateHasher::~StateHasher() { XXH3_freeState(static_cast<XXH3_state_t*>(state_)); }

void StateHasher::Flush() const {
  if (used_ == 0) return;
  XXH3_64bits_update(static_cast<XXH3_state_t*>(state_), buffer_, used_);
  used_ = 0;
}

void StateHasher::Add(const void* data, size_t bytes) {
  if (bytes <= kBuffer - used_) {
    if (bytes > 0) std::memcpy(buffer_ + used_, data, bytes);
    used_ += bytes;
    return;
  }
  Flush();
  if (bytes >= kBuffer) {
    XXH3_64bits_update(static_cast<XXH3_state_t*>(state_), data, bytes);
    return;
  }
  std::memcpy(buffer_, data, bytes);
  used_ = bytes;
}

uint64_t StateHasher::Digest() const {
  Flush();
  return XXH3_64bits_digest(static_cast<const XXH3_state_t*>(state_));
}

std::string StateHasher::ToHex(uint64_t hash) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(hash));
  return buf;
}

}  // namespace swarmsim
