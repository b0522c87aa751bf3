// A vector that takes 8 bytes until something is put in it: for per-robot
// lists that most robots never fill (writes to other robots' objects,
// copies and removals of robots, disabled scripts, collections, printed
// lines). 10,000 robots x 6 such lists as std::vector would be 1.4 MB of
// empty headers. The calls per-robot code makes of std::vector, same
// meaning; get() is the vector itself (made on first use).
#pragma once

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

namespace swarmsim {

template <class T>
class LazyVector {
 public:
  LazyVector() = default;
  LazyVector(LazyVector&&) noexcept = default;
  LazyVector& operator=(LazyVector&&) noexcept = default;
  LazyVector(const LazyVector& other)
      : v_(other.v_ ? std::make_unique<std::vector<T>>(*other.v_) : nullptr) {}
  LazyVector& operator=(const LazyVector& other) {
    if (this != &other) v_ = other.v_ ? std::make_unique<std::vector<T>>(*other.v_) : nullptr;
    return *this;
  }

  std::vector<T>& get() {
    if (!v_) v_ = std::make_unique<std::vector<T>>();
    return *v_;
  }
  bool empty() const { return !v_ || v_->empty(); }
  size_t size() const { return v_ ? v_->size() : 0; }
  void push_back(T value) { get().push_back(std::move(value)); }
  template <class... Args>
  T& emplace_back(Args&&... args) {
    return get().emplace_back(std::forward<Args>(args)...);
  }
  void pop_back() { v_->pop_back(); }
  T& back() { return v_->back(); }
  const T& back() const { return v_->back(); }
  T& operator[](size_t i) { return (*v_)[i]; }
  const T& operator[](size_t i) const { return (*v_)[i]; }
  // Empties it, keeping what it allocated (as std::vector::clear does).
  void clear() {
    if (v_) v_->clear();
  }
  T* begin() { return v_ ? v_->data() : nullptr; }
  T* end() { return v_ ? v_->data() + v_->size() : nullptr; }
  const T* begin() const { return v_ ? v_->data() : nullptr; }
  const T* end() const { return v_ ? v_->data() + v_->size() : nullptr; }

 private:
  std::unique_ptr<std::vector<T>> v_;
};

}  // namespace swarmsim
