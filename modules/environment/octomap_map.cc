#include "modules/environment/octomap_map.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <new>
#include <span>
#include <sstream>
#include <streambuf>
#include <string_view>

#include "framework/error.h"
#include "modules/environment/octomap_format.h"

namespace swarmsim::environment {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxHeaderBytes = size_t{1} << 20;  // the header's text, at most
constexpr int kKeyOffset = 32768;                    // octomap's tree_max_val (depth 16)
constexpr int kTreeSize = 65536;                     // keys per axis

// An istream over bytes in memory (what was checked is what the library reads).
class MemoryBuffer : public std::streambuf {
 public:
  MemoryBuffer(const char* data, size_t size) {
    char* p = const_cast<char*>(data);  // read only: no put area
    setg(p, p, p + size);
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                   std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type base = dir == std::ios_base::beg   ? 0
                          : dir == std::ios_base::cur ? gptr() - eback()
                                                      : egptr() - eback();
    const off_type target = base + off;
    if (target < 0 || target > egptr() - eback()) return pos_type(off_type(-1));
    setg(eback(), eback() + target, egptr());
    return pos_type(target);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

std::string Megabytes(double bytes) {
  std::ostringstream out;
  out.precision(bytes < 1e7 ? 2 : 0);
  out << std::fixed << bytes / (1 << 20) << " MiB";
  return out.str();
}

// Depth-first over the tree, children 0..7 (the file's order): the occupied
// leaves as boxes, cut to the voxel layers whose centres lie in the z range.
class BoxCollector {
 public:
  BoxCollector(const octomap::OcTree& tree, const OctomapOptions& options, EnvironmentMap* map,
               OctomapReport* report)
      : tree_(tree), options_(options), map_(map), report_(report) {}

  void Collect(const octomap::OcTreeNode* node, const int origin[3], int size) {
    if (!tree_.nodeHasChildren(node)) {
      if (tree_.isNodeOccupied(node)) AddLeaf(origin, size);
      return;
    }
    const int half = size / 2;
    for (unsigned int c = 0; c < 8; ++c) {
      if (!tree_.nodeChildExists(node, c)) continue;
      const int child[3] = {origin[0] + ((c & 1) ? half : 0), origin[1] + ((c & 2) ? half : 0),
                            origin[2] + ((c & 4) ? half : 0)};
      Collect(tree_.getNodeChild(node, c), child, half);
    }
  }

 private:
  double Coordinate(int key, double offset) const {
    return (key - kKeyOffset) * map_->resolution + offset;
  }

  void AddLeaf(const int origin[3], int size) {
    ++report_->occupied_leaves;
    // The voxel layers [j0, j1) whose centres are in [z_min, z_max].
    const double res = map_->resolution, z0 = Coordinate(origin[2], options_.offset.z);
    auto centre = [&](int j) { return z0 + (j + 0.5) * res; };
    int j0 = 0, j1 = size;
    if (std::isfinite(options_.z_min)) {
      j0 = static_cast<int>(
          std::clamp(std::ceil((options_.z_min - z0) / res - 0.5), 0.0, static_cast<double>(size)));
      while (j0 > 0 && centre(j0 - 1) >= options_.z_min) --j0;
      while (j0 < size && centre(j0) < options_.z_min) ++j0;
    }
    if (std::isfinite(options_.z_max)) {
      j1 = static_cast<int>(std::clamp(std::floor((options_.z_max - z0) / res - 0.5) + 1, 0.0,
                                       static_cast<double>(size)));
      while (j1 < size && centre(j1) <= options_.z_max) ++j1;
      while (j1 > 0 && centre(j1 - 1) > options_.z_max) --j1;
    }
    if (j0 >= j1) return;
    EnvironmentBox box;
    box.lo = {Coordinate(origin[0], options_.offset.x), Coordinate(origin[1], options_.offset.y),
              Coordinate(origin[2] + j0, options_.offset.z)};
    box.hi = {Coordinate(origin[0] + size, options_.offset.x),
              Coordinate(origin[1] + size, options_.offset.y),
              Coordinate(origin[2] + j1, options_.offset.z)};
    map_->boxes.push_back(box);
  }

  const octomap::OcTree& tree_;
  const OctomapOptions& options_;
  EnvironmentMap* map_;
  OctomapReport* report_;
};

[[noreturn]] void Fail(const std::string& name, const std::string& message) {
  throw Error("octomap " + name + ": " + message);
}

void CheckOptions(const OctomapOptions& o, const std::string& name) {
  if (!std::isfinite(o.offset.x) || !std::isfinite(o.offset.y) || !std::isfinite(o.offset.z))
    Fail(name, "the offset must be finite");
  if (!(o.z_min <= o.z_max)) Fail(name, "z_range needs min <= max");
  if (!(o.occupancy_threshold > 0 && o.occupancy_threshold < 1))
    Fail(name, "occupancy_threshold must be a probability between 0 and 1 (exclusive)");
  if (!(o.max_memory_mb > 0)) Fail(name, "max_memory_mb must be positive");
}

// The checked body read by the library into a tree, and its occupied
// leaves collected into `map`.
void ReadBoxes(const std::string& name, const OctomapHeader& header, std::string_view body,
               const OctomapOptions& options, EnvironmentMap* map, OctomapReport* report) {
  try {
    // The header was parsed as the library's readers (readBinary,
    // AbstractOcTree::read) parse it; their body readers read the body.
    // (The header readers print to stderr on every file: not called.)
    MemoryBuffer buffer(body.data(), body.size());
    std::istream stream(&buffer);
    auto tree = std::make_unique<octomap::OcTree>(header.resolution);
    if (header.size > 0) {
      if (header.format == OctomapFormat::kBinary)
        tree->readBinaryData(stream);
      else
        tree->readData(stream);
    }
    if (!stream) Fail(name, "the OctoMap library could not read it");
    if (tree->size() != header.size)
      Fail(name, "the OctoMap library read " + std::to_string(tree->size()) +
                     " nodes, the header says " + std::to_string(header.size));
    tree->setOccupancyThres(options.occupancy_threshold);
    // A tree whose root has no children is empty (the library would call the
    // whole root cube occupied).
    const octomap::OcTreeNode* root = tree->getRoot();
    if (root != nullptr && tree->nodeHasChildren(root)) {
      const int origin[3] = {0, 0, 0};
      BoxCollector(*tree, options, map, report).Collect(root, origin, kTreeSize);
    }
  } catch (const std::bad_alloc&) {
    Fail(name, "out of memory reading it");
  }
}

}  // namespace

EnvironmentMap ReadOctomap(const fs::path& file, const std::string& name,
                           const OctomapOptions& options, OctomapReport* report_out) {
  CheckOptions(options, name);
  OctomapReport report;
  std::error_code ec;
  if (!fs::exists(file, ec)) Fail(name, "no such file (looked for " + file.string() + ")");
  if (fs::is_directory(file, ec)) Fail(name, "is a folder, not a map file");
  const uintmax_t file_size = fs::file_size(file, ec);
  if (ec) Fail(name, "cannot read its size: " + ec.message());
  std::ifstream in(file, std::ios::binary);
  if (!in) Fail(name, std::string("cannot open it: ") + std::strerror(errno));

  // The header (text): at most kMaxHeaderBytes.
  std::string bytes(static_cast<size_t>(std::min<uintmax_t>(file_size, kMaxHeaderBytes)), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<size_t>(in.gcount()) != bytes.size()) Fail(name, "cannot read it");
  OctomapHeader header;
  try {
    header = ParseOctomapHeader(bytes);
  } catch (const Error& e) {
    Fail(name, e.what());
  }
  const bool binary = header.format == OctomapFormat::kBinary;
  if (!binary && header.id != "OcTree")
    Fail(
        name,
        "a .ot map of type " + header.id +
            "; swarmsim reads occupancy maps of type OcTree ('id OcTree' in a .ot file, or any .bt "
            "file); convert it to a .bt with octomap's tools");

  // Too large for memory? Decided from the header alone.
  const double estimate = static_cast<double>(header.size) * kBytesPerNode;
  if (estimate > options.max_memory_mb * (1 << 20)) {
    std::ostringstream m;
    m << "too large: its header says " << header.size << " nodes, about " << Megabytes(estimate)
      << " in memory (" << kBytesPerNode << " bytes per node), above the limit of "
      << options.max_memory_mb << " MiB (max_memory_mb); crop the map (e.g. octomap's "
      << "convert_octree with a bounding box) or raise max_memory_mb";
    Fail(name, m.str());
  }

  // The body: at most what a tree of that size can take (one more byte shows trailing data).
  const uintmax_t body_bound = (binary ? 2 : 5) * uintmax_t{header.size} + 1;
  const uintmax_t body_size = file_size - header.body_offset;
  const size_t have = bytes.size();  // read so far
  try {
    bytes.resize(header.body_offset + static_cast<size_t>(std::min(body_size, body_bound)));
  } catch (const std::bad_alloc&) {
    Fail(name, "out of memory reading it");
  }
  if (bytes.size() > have) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(have));
    in.read(bytes.data() + have, static_cast<std::streamsize>(bytes.size() - have));
    if (static_cast<size_t>(in.gcount()) != bytes.size() - have) Fail(name, "cannot read it");
  }
  const std::span<const uint8_t> body(
      reinterpret_cast<const uint8_t*>(bytes.data()) + header.body_offset,
      bytes.size() - header.body_offset);
  OctomapBodyCounts counts;
  try {
    counts = binary ? CheckBinaryBody(body, header.size) : CheckFullBody(body, header.size);
  } catch (const Error& e) {
    Fail(name, e.what());
  }
  report.nodes = counts.nodes;
  report.leaves = counts.leaves;
  if (body_size > counts.bytes)
    report.warnings.push_back("octomap " + name + ": " + std::to_string(body_size - counts.bytes) +
                              " bytes after the tree's last node are ignored");

  // The library reads exactly the checked bytes.
  EnvironmentMap map;
  map.source = name;
  map.resolution = header.resolution;
  map.max_grid_bytes = options.max_memory_mb * (1 << 20);
  ReadBoxes(name, header, {bytes.data() + header.body_offset, counts.bytes}, options, &map,
            &report);

  // Bounds, and what may surprise.
  report.kept_boxes = map.boxes.size();
  if (!map.boxes.empty()) {
    map.lo = map.boxes.front().lo;
    map.hi = map.boxes.front().hi;
    for (const EnvironmentBox& b : map.boxes) {
      map.lo = {std::min(map.lo.x, b.lo.x), std::min(map.lo.y, b.lo.y), std::min(map.lo.z, b.lo.z)};
      map.hi = {std::max(map.hi.x, b.hi.x), std::max(map.hi.y, b.hi.y), std::max(map.hi.z, b.hi.z)};
    }
  }
  if (report.occupied_leaves == 0) {
    report.warnings.push_back("octomap " + name +
                              ": the map has no occupied voxel; it adds nothing to the world");
  } else if (map.boxes.empty()) {
    std::ostringstream m;
    m << "octomap " << name << ": no occupied voxel has its centre in z_range [" << options.z_min
      << ", " << options.z_max << "]; the map adds nothing to the world";
    report.warnings.push_back(m.str());
  }
  if (report_out != nullptr) *report_out = std::move(report);
  return map;
}

}  // namespace swarmsim::environment
