// Reading recordings (FORMAT.md): scanning a file's chunks (what `swarmsim
// view` checks before it serves a folder, and re-checks as a run in
// progress appends), reading one chunk's payload, and replaying the step
// records into poses, colours, readings, paint and metric samples.
//
//   RecordingInfo info = ScanRecording(dir);   // throws swarmsim::Error with a user's message
//   std::cout << info.Describe() << "\n";     // "601 step records (steps 0..600), ..."
//   RecordingPlayer player(dir);
//   while (player.Next()) ... player.world_pose(id) ...
//
// Every read is bounded by what the file holds (chunk_reader.h): only a
// regular file is read, nothing is allocated beyond the bytes left in it
// (or kMaxChunkRawBytes for a payload, checked against its zstd frame), and
// every index and count in a chunk is checked before it is used. Errors are
// swarmsim::Error naming the file, the chunk and its byte offset.
//
// No third-party types here (zstd, xxHash and JSON stay in the .cc files).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/math.h"

namespace swarmsim::record {

struct ChunkInfo {      // 32 bytes
  uint64_t offset = 0;  // of its header, from the start of the file
  uint32_t step = 0;
  uint32_t stored_size = 0;  // compressed payload bytes after the header
  uint32_t raw_size = 0;
  uint32_t checksum = 0;  // XXH32 of the stored payload
  uint8_t kind = 0;       // ChunkKind (format.h)
};

struct RecordingInfo {
  std::filesystem::path file;
  uint64_t file_size = 0;   // bytes when scanned
  uint64_t valid_size = 0;  // bytes up to the end of the last whole chunk
  // The file ends inside a chunk: a run in progress, or one that was killed.
  // Every chunk before it is whole and valid.
  bool truncated = false;
  bool ended = false;      // has the end chunk (the run finished, or failed)
  std::string end_status;  // "ok", "error", "interrupted" (ended only)
  std::string end_error;   // the run's error message, if any
  int version_major = 0, version_minor = 0;
  std::string header_json;  // the header chunk's JSON text
  std::vector<ChunkInfo> chunks;
  int64_t step_records = 0;                 // keyframes and deltas
  int64_t first_step = -1, last_step = -1;  // of the step records (-1: none)
  // Where the scan is, for ContinueScan: the objects of the scene in force
  // (-1: no scene yet), and whether its keyframe is still to come.
  int64_t scene_objects = -1;
  bool keyframe_due = false;

  // One paragraph for a user: steps, size, whether the run ended or the
  // file was cut short ("... the file ends inside a chunk at byte 123456
  // (a run in progress, or killed): read the 312 whole step records before it").
  std::string Describe() const;
};

// The recording in `path`: a run's output folder (DIR/recording.swrec) or
// the file itself. Checks every chunk's header, checksum and zstd frame
// header, the header's format and version, and every header, scene and end
// chunk's JSON (every index and count in a scene against the scene itself,
// and its object count against the keyframe after it). Step records are
// decoded by RecordingPlayer. Throws swarmsim::Error with a message for a
// user: no recording in the folder, not a regular file, not a recording, a
// corrupt chunk (naming its number, byte offset and kind, and the field), a
// newer major format version (naming both). A truncated file is not an
// error (info.truncated).
RecordingInfo ScanRecording(const std::filesystem::path& path);
// Reads the chunks appended since `info` was scanned (a run in progress).
// Same errors.
void ContinueScan(RecordingInfo* info);

// The decompressed payload of one chunk. Throws swarmsim::Error naming the
// chunk if it cannot be read, its checksum is wrong or it does not decompress.
std::string ReadChunk(const std::filesystem::path& file, const ChunkInfo& chunk);

// One metric sample of a step record.
struct RecordedSample {
  std::string_view name;  // valid until the next Next() or SeekTo()
  int robot = -1;         // -1: swarm-level
  int64_t step = 0;
  double value = 0;
};

class RecordingFile;  // chunk_reader.h

// Replays a recording's step records in order (or from a keyframe).
class RecordingPlayer {
 public:
  // Scans `path` (ScanRecording's errors).
  explicit RecordingPlayer(const std::filesystem::path& path);
  ~RecordingPlayer();
  RecordingPlayer(const RecordingPlayer&) = delete;
  RecordingPlayer& operator=(const RecordingPlayer&) = delete;

  const RecordingInfo& info() const { return info_; }
  // Rescans for chunks a run appended since (ContinueScan).
  void Refresh();

  // Decodes the next step record; false when there is none. Throws
  // swarmsim::Error for a chunk that does not decode, naming it, its byte
  // offset and the byte of its payload.
  bool Next();
  // Decodes the step record of `step` (from the keyframe at or before it);
  // false if no step record has that step.
  bool SeekTo(int64_t step);

  // The state after the last decoded step record.
  int64_t step() const { return step_; }
  double time() const { return time_; }
  const std::string& scene_json() const { return scene_json_; }  // the scene in force
  size_t object_count() const { return root_.size(); }
  // The recorded id of robot `index`'s root (its first object); -1 if the
  // robot is not in the scene in force.
  int64_t robot_root(int robot_index) const;
  // The object's pose as recorded (in its robot root's frame, or the world's
  // for roots and scene objects), and in the world.
  Pose frame_pose(uint32_t id) const;
  Pose world_pose(uint32_t id) const;
  // The id's frame: its robot root's id, or -1 (the world).
  int64_t root_of(uint32_t id) const { return root_[id]; }
  uint32_t color_rgba(uint32_t id) const { return color_[id]; }  // r | g << 8 | b << 16 | on << 24
  uint16_t reading(uint32_t id) const { return reading_[id]; }   // as recorded (format.h)
  // The paint layer as recorded ((height x width x 3), empty without one).
  const std::vector<uint8_t>& paint_rgb() const { return paint_; }
  // The metric samples of the last decoded step record.
  const std::vector<RecordedSample>& samples() const { return samples_; }
  // The links of the last decoded step record (format 1.2): (id, id) pairs,
  // the first object linked to the second (a range-and-bearing board that
  // heard another), ascending by the first; empty without a links chunk.
  const std::vector<std::pair<uint32_t, uint32_t>>& links() const { return links_; }

 private:
  struct Quantized {
    int32_t x = 0, y = 0, z = 0;
    int16_t qw = 0, qx = 0, qy = 0, qz = 0;
  };
  void LoadScene(std::string text, const std::string& where);
  void Decode(const std::string& payload, bool keyframe, const std::string& where);
  void DecodeLinks(const std::string& payload, const std::string& where);

  std::unique_ptr<RecordingFile> file_;
  RecordingInfo info_;
  size_t next_chunk_ = 0;
  int64_t step_ = -1;
  double time_ = 0;
  std::string scene_json_;
  // The scene in force: its object count and robots' ranges; the arrays by
  // id below are sized to it by the keyframe after it (which lists every
  // object, so no scene claims more than its keyframe holds).
  uint64_t scene_objects_ = 0;
  std::vector<std::pair<uint64_t, uint64_t>> scene_ranges_;  // first, count
  bool keyframe_due_ = false;
  std::vector<int64_t> root_;                             // (ids)
  std::vector<std::pair<int64_t, int64_t>> robot_roots_;  // (robot index, root id), by index
  std::vector<Quantized> pose_;
  std::vector<uint32_t> color_;
  std::vector<uint16_t> reading_;
  std::vector<uint8_t> paint_;
  uint8_t paint_background_[3] = {255, 255, 255};
  std::vector<std::string> metric_names_;
  std::vector<RecordedSample> samples_;
  std::vector<std::pair<uint32_t, uint32_t>> links_;
};

}  // namespace swarmsim::record
