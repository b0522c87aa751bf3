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

Placer::CellKey Placer::CellOf(double x, double y) const {
  return {static_cast<int64_t>(std::floor(x / cell_size_)),
          static_cast<int64_t>(std::floor(y / cell_size_))};
}

void Placer::Insert(uint32_t body) {
  const Body& b = bodies_[body];
  cells_[CellOf(b.x, b.y)].push_back(body);
}

void Placer::Rebuild(double cell_size) {
  cell_size_ = cell_size;
  cells_.clear();
  for (uint32_t i = 0; i < bodies_.size(); ++i) Insert(i);
}

void Placer::AddBody(double x, double y, double radius) {
  bodies_.push_back({x, y, radius});
  max_body_radius_ = std::max(max_body_radius_, radius);
  if (cell_size_ > 0) Insert(static_cast<uint32_t>(bodies_.size() - 1));
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
  // Bodies: the cells within reach of any body that could touch this disc.
  const double reach = radius + max_body_radius_ + clearance;
  const CellKey lo = CellOf(x - reach, y - reach), hi = CellOf(x + reach, y + reach);
  for (int64_t cx = lo.x; cx <= hi.x; ++cx)
    for (int64_t cy = lo.y; cy <= hi.y; ++cy) {
      auto it = cells_.find({cx, cy});
      if (it == cells_.end()) continue;
      for (uint32_t i : it->second)
        if (!clear_of(bodies_[i])) return false;
    }
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
  if (cell != cell_size_) Rebuild(cell);
  out.reserve(static_cast<size_t>(count));
  Rng rng(seed_, kPlacementStream + stream);
  for (int64_t k = 0; k < count; ++k) {
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
