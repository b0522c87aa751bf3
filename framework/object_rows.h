// The dense row tables behind the scene's object types.
//
// Each object type keeps its objects' data in one table: row r belongs to
// the object at slot owners[r]. Scene holds one table per type, type-erased
// (RowTable), created by the type's descriptor (framework/object_type.h);
// typed access is a checked cast to Rows<Row>.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace swarmsim {

// The built-in object types; types registered by modules and plugins
// (Scene::RegisterType) take the values after kCollection (a module finds
// its own by name: Scene::FindType).
enum class ObjectType : uint8_t { kDummy, kShape, kJoint, kPluginSensor, kCollection };
inline constexpr int kBuiltinObjectTypes = 5;
inline constexpr int kMaxObjectTypes = 64;

// One type's rows, whatever their C++ type.
class RowTable {
 public:
  static constexpr uint32_t kNoOwner = UINT32_MAX;
  virtual ~RowTable() = default;
  virtual size_t size() const = 0;
  // A new last row for the object at slot `owner`: a copy of *row (of the
  // table's row type), or a default row when `row` is null. Returns its index.
  virtual uint32_t Append(const void* row, uint32_t owner) = 0;
  // A new last row copied from row `source` through `copy(source, fresh
  // default row)`, or the whole row when `copy` is null. Returns its index.
  virtual uint32_t AppendCopy(uint32_t source, uint32_t owner,
                              void (*copy)(const void* source, void* row)) = 0;
  // Moves the last row into `row` and drops the last one. Returns the slot
  // whose row index is now `row`, or kNoOwner when `row` was the last.
  virtual uint32_t SwapRemove(uint32_t row) = 0;
  virtual void Reserve(size_t rows) = 0;
  // `n` default rows at the end (owners kNoOwner), for CopyInto to fill: a
  // bulk copy's rows (Scene::DuplicateSubtrees), written on several threads.
  virtual void Grow(size_t n) = 0;
  // Row `row`, a default row Grow added, becomes a copy of row `source`
  // through `copy(source, row)` (or the whole row when `copy` is null), owned
  // by `owner`. Different rows may be written so on different threads.
  virtual void CopyInto(uint32_t source, uint32_t row, uint32_t owner,
                        void (*copy)(const void* source, void* row)) = 0;
  virtual void* At(uint32_t row) = 0;
  // The rows' reserved room past the last row: its start and bytes.
  virtual std::pair<const void*, size_t> Spare() const = 0;

  std::vector<uint32_t> owners;  // slot of each row's object (rows)
};

template <typename Row>
class Rows final : public RowTable {
 public:
  size_t size() const override { return rows.size(); }
  uint32_t Append(const void* row, uint32_t owner) override {
    rows.push_back(row != nullptr ? *static_cast<const Row*>(row) : Row{});
    owners.push_back(owner);
    return static_cast<uint32_t>(rows.size() - 1);
  }
  uint32_t AppendCopy(uint32_t source, uint32_t owner,
                      void (*copy)(const void* source, void* row)) override {
    Row row{};  // copied first: appending may move the source
    if (copy != nullptr)
      copy(&rows[source], &row);
    else
      row = rows[source];
    rows.push_back(std::move(row));
    owners.push_back(owner);
    return static_cast<uint32_t>(rows.size() - 1);
  }
  uint32_t SwapRemove(uint32_t row) override {
    const uint32_t last = static_cast<uint32_t>(rows.size() - 1);
    uint32_t moved = kNoOwner;
    if (row != last) {
      rows[row] = std::move(rows[last]);
      owners[row] = owners[last];
      moved = owners[row];
    }
    rows.pop_back();
    owners.pop_back();
    return moved;
  }
  void Reserve(size_t n) override {
    rows.reserve(n);
    owners.reserve(n);
  }
  void Grow(size_t n) override {
    rows.resize(rows.size() + n);
    owners.resize(owners.size() + n, kNoOwner);
  }
  void CopyInto(uint32_t source, uint32_t row, uint32_t owner,
                void (*copy)(const void* source, void* row)) override {
    if (copy != nullptr)
      copy(&rows[source], &rows[row]);
    else
      rows[row] = rows[source];
    owners[row] = owner;
  }
  void* At(uint32_t row) override { return &rows[row]; }
  std::pair<const void*, size_t> Spare() const override {
    return {rows.data() + rows.size(), (rows.capacity() - rows.size()) * sizeof(Row)};
  }

  std::vector<Row> rows;
};

}  // namespace swarmsim
