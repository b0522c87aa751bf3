#include "swarm/loader/placement.h"

#include <algorithm>
#include <cmath>

namespace swarmsim {

double Obstacle2::Distance(double px, double py) const {
  const double dx = px - x, dy = py - y;
  if (kind == Kind::kCircle) return std::hypot(dx, dy) - radius;
  // Into the box's frame, then the distance to an axis-aligned rectangle.
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double lx = c * dx + s * dy, ly = -s * dx + c * dy;
  const double qx = std::abs(lx) - half_x, qy = std::abs(ly) - half_y;
  const double outside = std::hypot(std::max(qx, 0.0), std::max(qy, 0.0));
  const double inside = std::min(std::max(qx, qy), 0.0);
  return outside + inside;
}

double Obstacle2::BoundingRadius() const {
  return kind == Kind::kCircle ? radius : std::hypot(half_x, half_y);
}

void Placer::Insert(uint32_t body) {
  const Body& b = bodies_[body];
  const int64_t i = CellIndex(b.x, grid_x0_), j = CellIndex(b.y, grid_y0_);
  if (i < 0 || i >= grid_nx_ || j < 0 || j >= grid_ny_) {
    outside_.push_back(body);
    return;
  }
  int32_t& head = head_[static_cast<size_t>(j * grid_nx_ + i)];
  next_[body] = head;
  head = static_cast<int32_t>(body);
}

void Placer::Rebuild(double cell_size, double lo_x, double lo_y, double hi_x, double hi_y,
                     size_t bodies) {
  // At most four cells per body to come (and 65,536 at least): a larger
  // cell than asked where the region is sparse. Any cell of at least
  // `cell_size` finds the same bodies.
  const double limit = std::max(65536.0, 4.0 * static_cast<double>(bodies));
  const double w = std::max(hi_x - lo_x, 0.0), h = std::max(hi_y - lo_y, 0.0);
  cell_size_ = std::max(cell_size, std::sqrt(w * h / limit));
  while ((std::floor(w / cell_size_) + 1) * (std::floor(h / cell_size_) + 1) > limit)
    cell_size_ *= 1.5;  // a long thin region
  grid_x0_ = lo_x;
  grid_y0_ = lo_y;
  grid_nx_ = static_cast<int64_t>(std::floor(w / cell_size_)) + 1;
  grid_ny_ = static_cast<int64_t>(std::floor(h / cell_size_)) + 1;
  head_.assign(static_cast<size_t>(grid_nx_ * grid_ny_), -1);
  next_.assign(bodies_.size(), -1);
  outside_.clear();
  for (uint32_t i = 0; i < bodies_.size(); ++i) Insert(i);
}

void Placer::AddBody(double x, double y, double radius) {
  bodies_.push_back({x, y, radius});
  max_body_radius_ = std::max(max_body_radius_, radius);
  if (cell_size_ > 0) {
    next_.push_back(-1);
    Insert(static_cast<uint32_t>(bodies_.size() - 1));
  }
}

bool Placer::NearMapCell(double x, double y, double keep) const {
  const double c = map_.cell;
  const auto first = [&](double v, double origin, int n) {
    return static_cast<int>(std::clamp(std::floor((v - origin) / c), -1.0, double(n)));
  };
  const int i0 = std::max(first(x - keep, map_.x0, map_.nx), 0);
  const int i1 = std::min(first(x + keep, map_.x0, map_.nx), map_.nx - 1);
  const int j0 = std::max(first(y - keep, map_.y0, map_.ny), 0);
  const int j1 = std::min(first(y + keep, map_.y0, map_.ny), map_.ny - 1);
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      if (!map_.at(i, j)) continue;
      // Distance from (x, y) to the cell's square.
      const double lo_x = map_.x0 + i * c, lo_y = map_.y0 + j * c;
      const double dx = std::max({lo_x - x, 0.0, x - (lo_x + c)});
      const double dy = std::max({lo_y - y, 0.0, y - (lo_y + c)});
      if (dx * dx + dy * dy < keep * keep) return true;
    }
  return false;
}

void Placer::KeepObstaclesReaching(double lo, double hi, double overlap) {
  std::erase_if(obstacles_,
                [&](const Obstacle2& o) { return !(o.hi > lo + overlap && o.lo < hi - overlap); });
}

bool Placer::IsFree(double x, double y, double radius, double clearance) const {
  // Obstacles: few, checked one by one behind a bounding-circle test.
  const double keep = radius + clearance;
  if (!map_.empty() && NearMapCell(x, y, keep)) return false;
  for (const Obstacle2& o : obstacles_) {
    if (std::hypot(x - o.x, y - o.y) - o.BoundingRadius() >= keep) continue;
    if (o.Distance(x, y) < keep) return false;
  }
  auto clear_of = [&](const Body& b) {
    const double dx = x - b.x, dy = y - b.y, min = radius + b.radius + clearance;
    return dx * dx + dy * dy >= min * min;
  };
  if (cell_size_ <= 0) {
    for (const Body& b : bodies_)
      if (!clear_of(b)) return false;
    return true;
  }
  // Bodies: the cells within reach of any body that could touch this disc
  // (cells past the grid hold none), and those outside the grid.
  const double reach = radius + max_body_radius_ + clearance;
  const int64_t i0 = std::max<int64_t>(CellIndex(x - reach, grid_x0_), 0);
  const int64_t i1 = std::min<int64_t>(CellIndex(x + reach, grid_x0_), grid_nx_ - 1);
  const int64_t j0 = std::max<int64_t>(CellIndex(y - reach, grid_y0_), 0);
  const int64_t j1 = std::min<int64_t>(CellIndex(y + reach, grid_y0_), grid_ny_ - 1);
  for (int64_t j = j0; j <= j1; ++j)
    for (int64_t i = i0; i <= i1; ++i)
      for (int32_t b = head_[static_cast<size_t>(j * grid_nx_ + i)]; b >= 0; b = next_[b])
        if (!clear_of(bodies_[static_cast<size_t>(b)])) return false;
  for (uint32_t b : outside_)
    if (!clear_of(bodies_[b])) return false;
  return true;
}

std::vector<Placement2> Placer::Distribute(const Region2& region, int64_t count, double radius,
                                           double clearance, uint64_t stream,
                                           std::optional<double> heading) {
  return Distribute(
      region, count, [radius](int64_t) { return radius; }, radius, clearance, stream, heading);
}

std::vector<Placement2> Placer::Distribute(const Region2& region, int64_t count,
                                           const std::function<double(int64_t)>& radius_of,
                                           double max_radius, double clearance, uint64_t stream,
                                           std::optional<double> heading) {
  std::vector<Placement2> out;
  if (count <= 0) return out;
  // A disc lies wholly inside the region: its centre in the rectangle shrunk by its radius.
  const double lo_x = region.min_x + max_radius, hi_x = region.max_x - max_radius;
  const double lo_y = region.min_y + max_radius, hi_y = region.max_y - max_radius;
  if (!(lo_x <= hi_x) || !(lo_y <= hi_y)) return out;
  // A cell holds about one body; a query then looks at 3 x 3 cells.
  max_body_radius_ = std::max(max_body_radius_, max_radius);
  const double extent = std::max(hi_x - lo_x, hi_y - lo_y);
  const double cell = std::max({2 * max_body_radius_ + clearance, 1e-3, extent * 1e-9});
  // The grid covers where this region's discs may go (and a disc's reach
  // about it); rebuilt for another cell size or region.
  const double margin = 2 * max_body_radius_ + clearance;
  const double g_lo_x = region.min_x - margin, g_lo_y = region.min_y - margin;
  const double g_hi_x = region.max_x + margin, g_hi_y = region.max_y + margin;
  const size_t bodies = bodies_.size() + static_cast<size_t>(count);
  if (cell_size_ <= 0 || cell > cell_size_ || g_lo_x < grid_x0_ || g_lo_y < grid_y0_ ||
      g_hi_x > grid_x0_ + static_cast<double>(grid_nx_) * cell_size_ ||
      g_hi_y > grid_y0_ + static_cast<double>(grid_ny_) * cell_size_ ||
      (cell_size_ > cell && 4 * bodies > head_.size()))  // coarser than needed for these many
    Rebuild(cell, g_lo_x, g_lo_y, g_hi_x, g_hi_y, bodies);
  out.reserve(static_cast<size_t>(count));
  Rng rng(seed_, kPlacementStream + stream);
  for (int64_t k = 0; k < count; ++k) {
    if (every_4096_ && k % 4096 == 4095) every_4096_(k);
    const double radius = radius_of(k);
    const double grow = max_radius - radius;  // a smaller disc may come closer to the edges
    bool placed = false;
    for (int attempt = 0; attempt < kMaxAttempts && !placed; ++attempt) {
      const double x = rng.Uniform(lo_x - grow, hi_x + grow);
      const double y = rng.Uniform(lo_y - grow, hi_y + grow);
      if (!IsFree(x, y, radius, clearance)) continue;
      const double yaw = heading ? *heading : rng.Uniform(-M_PI, M_PI);
      out.push_back({x, y, yaw});
      AddBody(x, y, radius);
      placed = true;
    }
    if (!placed) break;
  }
  return out;
}

namespace {

// The index of cell (x, y) along the Hilbert curve over an n x n grid
// (n a power of two; x, y < n).
uint64_t HilbertIndex(uint64_t n, uint64_t x, uint64_t y) {
  uint64_t d = 0;
  for (uint64_t s = n / 2; s > 0; s /= 2) {
    const uint64_t rx = (x & s) != 0 ? 1 : 0, ry = (y & s) != 0 ? 1 : 0;
    d += s * s * ((3 * rx) ^ ry);
    if (ry == 0) {  // rotate the quadrant
      if (rx == 1) {
        x = n - 1 - x;
        y = n - 1 - y;
      }
      std::swap(x, y);
    }
  }
  return d;
}

}  // namespace

void SortAlongCurve(std::vector<Placement2>* placements, double cell) {
  std::vector<Placement2>& p = *placements;
  if (p.size() < 2) return;
  double lo_x = p[0].x, lo_y = p[0].y, hi_x = p[0].x, hi_y = p[0].y;
  for (const Placement2& q : p) {
    lo_x = std::min(lo_x, q.x);
    lo_y = std::min(lo_y, q.y);
    hi_x = std::max(hi_x, q.x);
    hi_y = std::max(hi_y, q.y);
  }
  // At most 2^25 cells a side (a far finer grid than any arena needs).
  const double extent = std::max(hi_x - lo_x, hi_y - lo_y);
  const double size = std::max({cell, extent / static_cast<double>(1 << 24), 1e-9});
  uint64_t n = 1;
  while (static_cast<double>(n) * size <= extent) n *= 2;
  const auto index = [&](double v, double lo) {
    const double c = std::floor((v - lo) / size);
    return static_cast<uint64_t>(std::clamp(c, 0.0, static_cast<double>(n - 1)));
  };
  std::vector<std::pair<uint64_t, uint32_t>> keys(p.size());
  for (size_t k = 0; k < p.size(); ++k)
    keys[k] = {HilbertIndex(n, index(p[k].x, lo_x), index(p[k].y, lo_y)), static_cast<uint32_t>(k)};
  std::sort(keys.begin(), keys.end());  // ties by the old number: a total order
  std::vector<Placement2> sorted;
  sorted.reserve(p.size());
  for (const auto& [key, k] : keys) sorted.push_back(p[k]);
  p = std::move(sorted);
}

std::vector<Placement2> Placer::Lattice(const Region2& region, int64_t count, double radius,
                                        double spacing, bool hexagonal, int64_t columns,
                                        uint64_t stream, std::optional<double> heading,
                                        int64_t* first_bad) {
  std::vector<Placement2> out;
  *first_bad = -1;
  if (count <= 0 || columns <= 0) return out;
  const int64_t rows = (count + columns - 1) / columns;
  const int64_t used_columns = std::min(columns, count);
  const double pitch = hexagonal ? spacing * std::sqrt(3.0) / 2 : spacing;
  // The block's extent (a hexagonal block's shifted rows reach half a spacing further).
  const double width =
      static_cast<double>(used_columns - 1) * spacing + (hexagonal && rows > 1 ? spacing / 2 : 0);
  const double height = static_cast<double>(rows - 1) * pitch;
  const double x0 = (region.min_x + region.max_x - width) / 2;
  const double y0 = (region.min_y + region.max_y - height) / 2;
  Rng rng(seed_, kPlacementStream + stream);
  out.reserve(static_cast<size_t>(count));
  for (int64_t k = 0; k < count; ++k) {
    const int64_t row = k / columns, column = k % columns;
    const double x =
        x0 + static_cast<double>(column) * spacing + (hexagonal && row % 2 == 1 ? spacing / 2 : 0);
    const double y = y0 + static_cast<double>(row) * pitch;
    const bool inside = x - radius >= region.min_x && x + radius <= region.max_x &&
                        y - radius >= region.min_y && y + radius <= region.max_y;
    if (!inside || !IsFree(x, y, radius, 0)) {
      *first_bad = k;
      out.clear();
      return out;
    }
    out.push_back({x, y, heading ? *heading : rng.Uniform(-M_PI, M_PI)});
  }
  for (const Placement2& p : out) AddBody(p.x, p.y, radius);
  return out;
}

}  // namespace swarmsim
