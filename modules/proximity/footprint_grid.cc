#include "modules/proximity/footprint_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/prefault.h"

namespace swarmsim::proximity {
namespace {

constexpr uint32_t kNoCell = std::numeric_limits<uint32_t>::max();
constexpr double kMaxCellsPerEntry = 4;

// Do the boxes meet (closed)?
bool Meets(const Aabb2& a, const Aabb2& b) {
  return a.min_x <= b.max_x && a.max_x >= b.min_x && a.min_y <= b.max_y && a.max_y >= b.min_y;
}

}  // namespace

void FootprintGrid::Build(std::span<const Aabb2> squares, std::span<const int32_t> instances,
                          std::span<const ObjectId> ids, TaskScheduler* scheduler) {
  const size_t n = squares.size();
  // One group per robot (the union of its squares), one per shape of no robot.
  int32_t max_instance = -1;
  size_t no_robot = 0;
  for (int32_t instance : instances) {
    max_instance = std::max(max_instance, instance);
    no_robot += instance < 0 ? 1 : 0;
  }
  if (scheduler != nullptr) {
    // At most a group per robot and per shape of no robot.
    const size_t groups = std::min(n, size_t(max_instance + 1) + no_robot);
    Prefault prefault;
    // (Every array is written whole below: its contents need no keeping.)
    const auto grow = [&](auto& v, size_t size) {
      if (v.capacity() < size) v.clear();
      prefault.Reserve(v, size);
    };
    grow(squares_, n);
    grow(ids_, n);
    grow(group_of_shape_, n);
    grow(members_, n);
    grow(group_of_instance_, size_t(max_instance + 1));
    grow(group_squares_, groups);
    grow(group_instance_, groups);
    grow(group_start_, groups + 1);
    grow(cell_of_group_, groups);
    grow(cell_entries_, groups);
    prefault.Run(*scheduler);
  }
  squares_.assign(squares.begin(), squares.end());
  ids_.assign(ids.begin(), ids.end());
  group_of_instance_.assign(size_t(max_instance + 1), -1);
  group_squares_.clear();
  group_instance_.clear();
  group_of_shape_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const int32_t instance = instances[i];
    // (A NaN square meets nothing; in a union it stands for everything, so
    // that its group's other squares are still found.)
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const Aabb2& given = squares[i];
    const Aabb2 s = std::isnan(given.min_x + given.min_y + given.max_x + given.max_y)
                        ? Aabb2{-kInf, -kInf, kInf, kInf}
                        : given;
    int32_t group = instance >= 0 ? group_of_instance_[size_t(instance)] : -1;
    if (group < 0) {
      group = static_cast<int32_t>(group_squares_.size());
      group_squares_.push_back(s);
      group_instance_.push_back(instance);
      if (instance >= 0) group_of_instance_[size_t(instance)] = group;
    } else {
      Aabb2& g = group_squares_[size_t(group)];
      g = {std::min(g.min_x, s.min_x), std::min(g.min_y, s.min_y), std::max(g.max_x, s.max_x),
           std::max(g.max_y, s.max_y)};
    }
    group_of_shape_[i] = static_cast<uint32_t>(group);
  }
  const size_t groups = group_squares_.size();
  // Members of each group, ascending.
  group_start_.assign(groups + 1, 0);
  for (size_t i = 0; i < n; ++i) ++group_start_[group_of_shape_[i] + 1];
  for (size_t g = 0; g < groups; ++g) group_start_[g + 1] += group_start_[g];
  members_.resize(n);
  for (size_t i = 0; i < n; ++i) members_[group_start_[group_of_shape_[i]]++] = uint32_t(i);
  for (size_t g = groups; g > 0; --g) group_start_[g] = group_start_[g - 1];
  group_start_[0] = 0;

  // The grid: bounds and mean half edge of the finite groups.
  auto finite = [](const Aabb2& s) {
    return std::isfinite(s.min_x) && std::isfinite(s.min_y) && std::isfinite(s.max_x) &&
           std::isfinite(s.max_y) && s.min_x <= s.max_x && s.min_y <= s.max_y;
  };
  auto half = [](const Aabb2& s) { return 0.5 * std::max(s.max_x - s.min_x, s.max_y - s.min_y); };
  oversize_.clear();
  cells_x_ = cells_y_ = 0;
  max_half_ = 0;
  double min_x = std::numeric_limits<double>::infinity(), min_y = min_x;
  double max_x = -min_x, max_y = -min_x, half_sum = 0;
  size_t finite_groups = 0;
  for (const Aabb2& s : group_squares_) {
    if (!finite(s)) continue;
    const double cx = 0.5 * (s.min_x + s.max_x), cy = 0.5 * (s.min_y + s.max_y);
    min_x = std::min(min_x, cx), max_x = std::max(max_x, cx);
    min_y = std::min(min_y, cy), max_y = std::max(max_y, cy);
    half_sum += half(s);
    ++finite_groups;
  }
  const double width = max_x - min_x, height = max_y - min_y;
  double cell = 0;
  if (finite_groups > 0 && std::isfinite(width) && std::isfinite(height)) {
    // About one entry per cell, and at least four mean half edges.
    const double spacing = width > 0 && height > 0       ? std::sqrt(width * height / finite_groups)
                           : std::max(width, height) > 0 ? std::max(width, height) / finite_groups
                                                         : 1.0;
    cell = std::max(spacing, 4 * half_sum / finite_groups);
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    const double max_cells = kMaxCellsPerEntry * finite_groups;
    double nx = std::floor(width / cell) + 1, ny = std::floor(height / cell) + 1;
    while (nx * ny > max_cells) {
      cell *= std::max(std::sqrt(nx * ny / max_cells), 1.0 + 1e-9);
      nx = std::floor(width / cell) + 1, ny = std::floor(height / cell) + 1;
    }
    if (std::isfinite(cell) && cell > 0) {
      origin_x_ = min_x, origin_y_ = min_y;
      inv_cell_size_ = 1 / cell;
      cells_x_ = static_cast<int>(nx), cells_y_ = static_cast<int>(ny);
    }
  }

  // Each group's cell (or the oversize list), then a counting sort.
  const size_t cell_count = size_t(cells_x_) * size_t(cells_y_);
  cell_start_.assign(cell_count + 1, 0);
  cell_of_group_.resize(groups);
  for (size_t g = 0; g < groups; ++g) {
    const Aabb2& s = group_squares_[g];
    if (cell_count == 0 || !finite(s) || half(s) > cell / 2) {
      cell_of_group_[g] = kNoCell;
      oversize_.push_back({s, group_instance_[g], uint32_t(g)});
      continue;
    }
    const double cx = 0.5 * (s.min_x + s.max_x), cy = 0.5 * (s.min_y + s.max_y);
    const int ix = std::min(static_cast<int>((cx - origin_x_) * inv_cell_size_), cells_x_ - 1);
    const int iy = std::min(static_cast<int>((cy - origin_y_) * inv_cell_size_), cells_y_ - 1);
    const uint32_t c = static_cast<uint32_t>(iy) * static_cast<uint32_t>(cells_x_) + ix;
    cell_of_group_[g] = c;
    ++cell_start_[c];
    max_half_ = std::max({max_half_, cx - s.min_x, s.max_x - cx, cy - s.min_y, s.max_y - cy});
  }
  uint32_t running = 0;
  for (size_t c = 0; c < cell_count; ++c) running = (cell_start_[c] += running);
  cell_start_[cell_count] = running;
  cell_entries_.resize(running);
  for (size_t g = groups; g-- > 0;) {
    if (cell_of_group_[g] == kNoCell) continue;
    cell_entries_[--cell_start_[cell_of_group_[g]]] = {group_squares_[g], group_instance_[g],
                                                       uint32_t(g)};
  }
}

template <class Visit>
bool FootprintGrid::Scan(const Aabb2& box, Visit&& visit) const {
  CellRange c;
  if (CellsReached(box, max_half_, origin_x_, origin_y_, inv_cell_size_, cells_x_, cells_y_, &c)) {
    for (int iy = c.iy0; iy <= c.iy1; ++iy) {
      const size_t row = size_t(iy) * size_t(cells_x_);
      for (uint32_t e = cell_start_[row + c.ix0]; e < cell_start_[row + c.ix1 + 1]; ++e)
        if (visit(cell_entries_[e])) return true;
    }
  }
  for (const Entry& entry : oversize_)
    if (visit(entry)) return true;
  return false;
}

bool FootprintGrid::AnyOther(const Aabb2& box, int instance, std::span<const ObjectId> skip) const {
  return Scan(box, [&](const Entry& entry) {
    if ((instance >= 0 && entry.instance == instance) || !Meets(entry.square, box)) return false;
    if (skip.empty()) return true;
    for (uint32_t m = group_start_[entry.group]; m < group_start_[entry.group + 1]; ++m) {
      const uint32_t s = members_[m];
      if (Meets(squares_[s], box) && std::find(skip.begin(), skip.end(), ids_[s]) == skip.end())
        return true;
    }
    return false;
  });
}

void FootprintGrid::Others(const Aabb2& box, int instance, std::span<const ObjectId> skip,
                           std::vector<uint32_t>* out) const {
  out->clear();
  Scan(box, [&](const Entry& entry) {
    if ((instance >= 0 && entry.instance == instance) || !Meets(entry.square, box)) return false;
    for (uint32_t m = group_start_[entry.group]; m < group_start_[entry.group + 1]; ++m) {
      const uint32_t s = members_[m];
      if (Meets(squares_[s], box) && std::find(skip.begin(), skip.end(), ids_[s]) == skip.end())
        out->push_back(s);
    }
    return false;
  });
  std::sort(out->begin(), out->end());
}

}  // namespace swarmsim::proximity
