// Settings apart from state (MuJoCo's mjModel beside mjData).
//
// An object type's row holds its per-copy state (a joint's position, a
// sensor's reading) beside a Shared<Settings>: the constant part (ranges,
// limits, angles, names of what it detects), shared by every copy made from
// one model entry. Copying a row, as placing ten thousand robots does,
// copies the state and one pointer; the settings exist once per model entry.
// Edit() is copy on write: when a script, a scale or a per-copy --set changes
// one copy's setting, that row gets its own settings first and the other
// copies keep theirs.
//
// Phase code reads settings through operator-> (const). The state hash reads
// state only. Thread safety: rows of different robots may Edit() at the same
// time (the reference count is atomic); one row is edited by one thread.
//
// Bulk copies (a million robots' rows written on every thread) would make
// every thread increment the same few reference counts, one cache line
// passed between cores per row. Inside a CountCopiesLocally scope, a
// thread's copies count their references in the scope and add them once
// when it ends.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>

namespace swarmsim {

namespace shared_detail {
// The references copies on this thread have taken inside CountCopiesLocally
// scopes and not yet added: a few blocks' counts (a robot's rows share a
// handful of settings).
struct LocalCounts {
  static constexpr int kBlocks = 8;
  std::atomic<uint32_t>* refs[kBlocks];
  uint32_t count[kBlocks];
  int used = 0;
  int depth = 0;  // scopes open on this thread

  // Counts one reference to `r` here; false when the table is full (the
  // caller adds it at once).
  bool Count(std::atomic<uint32_t>* r) {
    for (int i = 0; i < used; ++i)
      if (refs[i] == r) return ++count[i], true;
    if (used == kBlocks) return false;
    refs[used] = r;
    count[used++] = 1;
    return true;
  }
  void AddAll() {
    for (int i = 0; i < used; ++i) refs[i]->fetch_add(count[i], std::memory_order_relaxed);
    used = 0;
  }
};
inline thread_local LocalCounts local_counts;
}  // namespace shared_detail

// While one is open on a thread, Shared copies made on that thread add
// their references when it closes, not one by one. Only around copies of
// rows that stay alive through the scope and that nothing releases or
// Edit()s in it (their counts are short until it closes): Scene's bulk row
// copies.
class CountCopiesLocally {
 public:
  CountCopiesLocally() { ++shared_detail::local_counts.depth; }
  ~CountCopiesLocally() {
    shared_detail::LocalCounts& local = shared_detail::local_counts;
    if (--local.depth == 0) local.AddAll();
  }
  CountCopiesLocally(const CountCopiesLocally&) = delete;
  CountCopiesLocally& operator=(const CountCopiesLocally&) = delete;
};

template <class S>
class Shared {
 public:
  // The default settings (S{}), shared by every default row without an
  // allocation.
  Shared() noexcept = default;
  explicit Shared(S settings) : block_(new Block{{1}, std::move(settings)}) {}
  Shared(const Shared& other) noexcept : block_(other.block_) { Retain(); }
  Shared(Shared&& other) noexcept : block_(std::exchange(other.block_, nullptr)) {}
  Shared& operator=(const Shared& other) noexcept {
    if (block_ != other.block_) {
      Release();
      block_ = other.block_;
      Retain();
    }
    return *this;
  }
  Shared& operator=(Shared&& other) noexcept {
    if (this != &other) {
      Release();
      block_ = std::exchange(other.block_, nullptr);
    }
    return *this;
  }
  ~Shared() { Release(); }

  const S& operator*() const { return block_ != nullptr ? block_->settings : kDefault; }
  const S* operator->() const { return &**this; }

  // This row's own settings, to change: copied first if other rows share
  // them (or if they are the shared defaults).
  S& Edit() {
    if (block_ == nullptr || block_->refs.load(std::memory_order_acquire) != 1) {
      Block* own = new Block{{1}, **this};
      Release();
      block_ = own;
    }
    return block_->settings;
  }

  // Whether `other` refers to the same settings (a copy that no one edited).
  bool SameAs(const Shared& other) const { return &**this == &*other; }

 private:
  struct Block {
    std::atomic<uint32_t> refs;
    S settings;
  };
  void Retain() noexcept {
    if (block_ == nullptr) return;
    shared_detail::LocalCounts& local = shared_detail::local_counts;
    if (local.depth > 0 && local.Count(&block_->refs)) return;
    block_->refs.fetch_add(1, std::memory_order_relaxed);
  }
  void Release() noexcept {
    if (block_ != nullptr && block_->refs.fetch_sub(1, std::memory_order_acq_rel) == 1)
      delete block_;
    block_ = nullptr;
  }

  static inline const S kDefault{};
  Block* block_ = nullptr;
};

// The settings of a table whose rows are Shared<S> (shapes), read as a
// span of S: view[r] is row r's settings.
template <class S>
class SettingsView {
 public:
  explicit SettingsView(std::span<const Shared<S>> rows) : rows_(rows) {}
  size_t size() const { return rows_.size(); }
  bool empty() const { return rows_.empty(); }
  const S& operator[](size_t r) const { return *rows_[r]; }

  class Iterator {
   public:
    explicit Iterator(const Shared<S>* at) : at_(at) {}
    const S& operator*() const { return **at_; }
    Iterator& operator++() {
      ++at_;
      return *this;
    }
    bool operator==(const Iterator& other) const { return at_ == other.at_; }

   private:
    const Shared<S>* at_;
  };
  Iterator begin() const { return Iterator(rows_.data()); }
  Iterator end() const { return Iterator(rows_.data() + rows_.size()); }

 private:
  std::span<const Shared<S>> rows_;
};

}  // namespace swarmsim
