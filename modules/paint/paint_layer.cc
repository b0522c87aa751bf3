#include "modules/paint/paint_layer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world_state.h"
#include "modules/paint/png_io.h"

namespace swarmsim::paint {

namespace {

constexpr double kMaxPixels = 100e6;
constexpr int64_t kRobotGrain = 16;

uint8_t ToByte(double c) {
  return static_cast<uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255));
}

}  // namespace

PaintLayer::PaintLayer(World* world, const PaintSettings& settings)
    : world_(world), settings_(settings) {
  const double res = settings_.resolution;
  if (!(res > 0) || !std::isfinite(res))
    throw Error("paint: the resolution must be a positive number of metres per pixel");
  const double w = settings_.max_x - settings_.min_x, h = settings_.max_y - settings_.min_y;
  if (!(w > 0) || !(h > 0) || !std::isfinite(w) || !std::isfinite(h))
    throw Error("paint: the painted area must have a positive width and depth");
  const double cols = std::ceil(w / res - 1e-9), rows = std::ceil(h / res - 1e-9);
  if (cols * rows > kMaxPixels)
    throw Error("paint: a " + std::to_string(static_cast<int64_t>(cols)) + " x " +
                std::to_string(static_cast<int64_t>(rows)) +
                " image is over 100 megapixels; use a coarser resolution");
  width_ = static_cast<int>(cols);
  height_ = static_cast<int>(rows);
  const size_t n = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  painted_.assign(n, 0);
  rgb_.resize(3 * n);
  // Over a floor: each pixel starts as the floor's colour at its centre.
  floor_ = world_->floor_layer();
  if (floor_ != nullptr) {
    const FloorArea area = floor_->floor_area();
    floor_marked_.assign(n, 0);
    for (int row = 0; row < height_; ++row)
      for (int col = 0; col < width_; ++col) {
        const Vec3 c = PixelCentre(col, row);
        const int64_t pixel = FloorPixelAt(area, c.x, c.y);
        if (pixel < 0 || !floor_->floor_marked(static_cast<int>(pixel % area.width),
                                               static_cast<int>(pixel / area.width)))
          continue;  // the floor's background there: ours
        floor_marked_[static_cast<size_t>(row) * width_ + col] = 1;
      }
  }
  for (size_t p = 0; p < n; ++p) StartColor(p, &rgb_[3 * p]);
  world_->set_floor_layer(this);
}

void PaintLayer::StartColor(size_t p, uint8_t out[3]) const {
  if (!floor_marked_.empty() && floor_marked_[p] != 0) {
    const FloorArea area = floor_->floor_area();
    const Vec3 c = PixelCentre(static_cast<int>(p % width_), static_cast<int>(p / width_));
    const int64_t pixel = FloorPixelAt(area, c.x, c.y);
    std::copy_n(&floor_->floor_rgb()[3 * pixel], 3, out);
    return;
  }
  out[0] = ToByte(settings_.background.x);
  out[1] = ToByte(settings_.background.y);
  out[2] = ToByte(settings_.background.z);
}

bool PaintLayer::SaveState(const World&, StateWriter* out) const {
  // Runs of painted pixels: (first, count), then their RGB.
  const size_t n = painted_.size();
  std::vector<std::pair<uint32_t, uint32_t>> runs;
  for (size_t p = 0; p < n;) {
    if (painted_[p] == 0) {
      ++p;
      continue;
    }
    const size_t first = p;
    while (p < n && painted_[p] != 0) ++p;
    runs.emplace_back(static_cast<uint32_t>(first), static_cast<uint32_t>(p - first));
  }
  out->Put<uint64_t>(runs.size());
  for (const auto& [first, count] : runs) {
    out->Put(first);
    out->Put(count);
    out->PutBytes(&rgb_[3 * size_t{first}], 3 * size_t{count});
  }
  return true;
}

void PaintLayer::LoadState(StateReader* in, World*) {
  const size_t n = painted_.size();
  for (size_t p = 0; p < n; ++p)
    if (painted_[p] != 0) {
      painted_[p] = 0;
      StartColor(p, &rgb_[3 * p]);
    }
  const uint64_t runs = in->GetCount(2 * sizeof(uint32_t));
  size_t end = 0;  // runs come in order and do not touch
  for (uint64_t i = 0; i < runs; ++i) {
    const auto first = in->Get<uint32_t>();
    const auto count = in->Get<uint32_t>();
    if (first < end || count == 0 || count > n - std::min<size_t>(first, n))
      in->Fail("a run of painted pixels outside the paint layer or out of order");
    in->GetBytes(&rgb_[3 * size_t{first}], 3 * size_t{count});
    std::fill_n(painted_.begin() + first, count, uint8_t{1});
    end = size_t{first} + count + 1;
  }
}

PaintLayer::~PaintLayer() {
  if (world_->floor_layer() == this) world_->set_floor_layer(nullptr);
}

FloorArea PaintLayer::floor_area() const {
  return {settings_.min_x,      settings_.min_y, settings_.max_x, settings_.max_y,
          settings_.resolution, width_,          height_,         settings_.background};
}

const Rows<PaintNozzleData>& PaintLayer::Nozzles(const Scene& scene) const {
  ObjectType type;
  if (!scene.FindType(kPaintNozzleTypeName, &type))
    throw Error("paint: the scene has no paint nozzle type (modules/paint is not registered)");
  return scene.rows<PaintNozzleData>(type);
}

Vec3 PaintLayer::PixelCentre(int column, int row) const {
  const double res = settings_.resolution;
  return {settings_.min_x + (column + 0.5) * res, settings_.max_y - (row + 0.5) * res, 0};
}

int64_t PaintLayer::painted_count() const {
  return std::count(painted_.begin(), painted_.end(), uint8_t{1});
}

void PaintLayer::RefreshNozzles(const Scene& scene) {
  nozzles_ = &Nozzles(scene);  // one look-up a step, not one a nozzle
  // Rebuilt only when objects were added or removed (slot order: deterministic).
  if (nozzles_version_ == scene.structure_version()) return;
  nozzles_version_ = scene.structure_version();
  robot_nozzles_.assign(scene.instances().size(), {});
  strokes_.resize(scene.instances().size());
  scene_nozzles_.clear();
  const std::vector<uint32_t>& owners = nozzles_->owners;
  std::vector<uint32_t> slots(owners.begin(), owners.end());
  std::sort(slots.begin(), slots.end());
  for (uint32_t slot : slots) {
    const int instance = scene.instance_of_at(slot);
    if (instance >= 0)
      robot_nozzles_[instance].push_back(slot);
    else
      scene_nozzles_.push_back(slot);
  }
}

void PaintLayer::Stamp(const Scene& scene, uint32_t slot, std::vector<Stroke>* out) const {
  const PaintNozzleData& nozzle = nozzles_->rows[scene.row_at(slot)];
  if (!nozzle.enabled) return;
  const Vec3& p = scene.world_pose_at(slot).p;
  if (!(p.z >= 0)) return;  // below the floor (or not finite)
  const double res = settings_.resolution, r = nozzle.radius;
  // Candidate columns and rows, then the exact test on each pixel centre.
  const double c_lo = std::floor((p.x - r - settings_.min_x) / res);
  const double c_hi = std::floor((p.x + r - settings_.min_x) / res);
  const double r_lo = std::floor((settings_.max_y - (p.y + r)) / res);
  const double r_hi = std::floor((settings_.max_y - (p.y - r)) / res);
  if (c_hi < 0 || r_hi < 0 || c_lo >= width_ || r_lo >= height_) return;
  const int c0 = static_cast<int>(std::max(0.0, c_lo));
  const int c1 = static_cast<int>(std::min<double>(width_ - 1, c_hi));
  const int r0 = static_cast<int>(std::max(0.0, r_lo));
  const int r1 = static_cast<int>(std::min<double>(height_ - 1, r_hi));
  const uint8_t red = ToByte(nozzle.color.x), green = ToByte(nozzle.color.y),
                blue = ToByte(nozzle.color.z);
  for (int row = r0; row <= r1; ++row) {
    const double dy = settings_.max_y - (row + 0.5) * res - p.y;
    for (int col = c0; col <= c1; ++col) {
      const double dx = settings_.min_x + (col + 0.5) * res - p.x;
      if (dx * dx + dy * dy <= r * r)
        out->push_back({static_cast<uint32_t>(row * width_ + col), red, green, blue});
    }
  }
}

void PaintLayer::Apply(std::vector<Stroke>* strokes) {
  for (const Stroke& s : *strokes) {
    uint8_t* px = &rgb_[3 * static_cast<size_t>(s.pixel)];
    px[0] = s.r;
    px[1] = s.g;
    px[2] = s.b;
    painted_[s.pixel] = 1;
  }
  strokes->clear();
}

void PaintLayer::Record(const World& world, std::vector<MetricSample>* /*out*/) {
  const Scene& scene = world.scene();
  RefreshNozzles(scene);
  // Each robot stamps into its own buffer; then the buffers in robot order.
  const int64_t robots = static_cast<int64_t>(robot_nozzles_.size());
  world_->scheduler().ParallelFor(0, robots, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      if (robot_nozzles_[r].empty() || !scene.instances()[r].alive) continue;
      for (uint32_t slot : robot_nozzles_[r]) Stamp(scene, slot, &strokes_[r]);
    }
  });
  for (auto& strokes : strokes_) Apply(&strokes);
  for (uint32_t slot : scene_nozzles_) Stamp(scene, slot, &scene_strokes_);
  Apply(&scene_strokes_);
}

void PaintLayer::WriteOutputs(const std::filesystem::path& dir) const {
  WritePng(dir / "paint.png", width_, height_, rgb_);
}

void PaintLayer::ListOutputs(std::vector<OutputFile>* out) const {
  out->push_back({"image", "paint.png", "the floor paint layer"});
}

ModuleDescriptor PaintModule() {
  return {{"record", "paint", "1.0",
           "the floor paint layer paint nozzles mark (paint.png), world file key paint:"},
          PhaseBit(Phase::kRecord),
          200,
          /*every_world=*/false,
          [](World* world, const void* config) -> std::unique_ptr<Module> {
            if (config == nullptr) throw Error("the paint module needs its settings (paint:)");
            return std::make_unique<PaintLayer>(world, *static_cast<const PaintSettings*>(config));
          }};
}

}  // namespace swarmsim::paint
