// The JSON chunks of a recording (header, scene, end; FORMAT.md), read into
// what the readers use, every index and count checked against the chunk
// itself (internal to swarm/record). Parsed as a stream of events, not into
// a document tree: memory grows with the robots and objects described, not
// with whatever else a chunk holds. Errors are swarmsim::Error beginning
// with `where` (chunk_reader.h ChunkPlace) and naming the field
// ("robots[0].first is 1000000, ...") or the byte of the JSON text.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace swarmsim::record {

// A header chunk. Only the format name and version are checked while
// parsing (a newer major version may differ in everything else); the first
// other problem is kept in `problem` for the caller to raise after the
// version check.
struct HeaderFields {
  bool is_object = false;
  std::string format;  // "" when absent or not a string
  bool has_version = false;
  int version_major = 0, version_minor = 0;
  bool has_paint = false;
  uint32_t paint_width = 0, paint_height = 0;  // cells; width x height <= kMaxPaintCells
  double paint_background[3] = {1, 1, 1};      // RGB 0..1
  std::vector<std::string> metrics;
  std::string problem;  // "" or the first field that is wrong, in words
};
HeaderFields ParseHeaderJson(std::string_view text, const std::string& where);

// A scene chunk. Robots are checked against their templates and the object
// count, and robots' ranges and the other objects' ids cover 0 ..
// object_count - 1 exactly once.
struct SceneRobot {  // 24 bytes
  int64_t index = 0;
  uint64_t first = 0;  // its root's id
  uint64_t count = 0;  // ids first .. first + count - 1
};
struct SceneFields {
  uint64_t object_count = 0;
  std::vector<SceneRobot> robots;  // in file order
};
SceneFields ParseSceneJson(std::string_view text, const std::string& where);

// An end chunk.
struct EndFields {
  std::string status, error;
};
EndFields ParseEndJson(std::string_view text, const std::string& where);

}  // namespace swarmsim::record
