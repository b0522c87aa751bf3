#include "swarm/record/reader.h"

#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>

#include "framework/error.h"
#include "swarm/record/chunk_json.h"
#include "swarm/record/chunk_reader.h"
#include "swarm/record/format.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;

// "1.25 MB", "3.2 kB", "512 bytes": a short recording is not "0.00 MB".
std::string SizeText(uint64_t bytes) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  if (bytes < 1000) {
    out << bytes << (bytes == 1 ? " byte" : " bytes");
  } else if (bytes < 1000000) {
    out.precision(1);
    out << static_cast<double>(bytes) / 1e3 << " kB";
  } else {
    out.precision(2);
    out << static_cast<double>(bytes) / 1e6 << " MB";
  }
  return out.str();
}

// The header chunk's JSON: format name and version first (a newer major
// version may differ in everything else), then its other fields.
void CheckHeader(RecordingInfo* info, std::string text, const std::string& where) {
  const HeaderFields header = ParseHeaderJson(text, where);
  if (!header.is_object || header.format != kFormatName || !header.has_version)
    throw Error(info->file.string() + " is not a swarmsim recording (its header names no " +
                kFormatName + " version)");
  info->version_major = header.version_major;
  info->version_minor = header.version_minor;
  if (info->version_major > kVersionMajor)
    throw Error(info->file.string() + " is a recording of format version " +
                std::to_string(info->version_major) + "." + std::to_string(info->version_minor) +
                ", newer than this swarmsim reads (" + std::to_string(kVersionMajor) + "." +
                std::to_string(kVersionMinor) + "): use a newer swarmsim");
  if (!header.problem.empty()) throw Error(where + ": " + header.problem);
  info->header_json = std::move(text);
}

// What one whole chunk says, checked (ContinueScan): its payload's frame,
// and the JSON of header, scene and end chunks.
void CheckChunk(RecordingInfo* info, size_t index, const ChunkInfo& c, const std::string& stored,
                const std::string& where) {
  CheckFrame(stored, c.raw_size, where);
  switch (static_cast<ChunkKind>(c.kind)) {
    case ChunkKind::kHeader:
      if (index != 0) throw Error(where + ": a second header chunk");
      CheckHeader(info, Decompress(stored, c.raw_size, where), where);
      break;
    case ChunkKind::kScene:
      info->scene_objects = static_cast<int64_t>(
          ParseSceneJson(Decompress(stored, c.raw_size, where), where).object_count);
      info->keyframe_due = true;
      break;
    case ChunkKind::kKeyframe:
    case ChunkKind::kDelta:
      if (info->scene_objects < 0) throw Error(where + ": a step record before any scene chunk");
      if (info->keyframe_due) {
        // The keyframe after a scene lists every object's pose.
        if (c.kind != static_cast<uint8_t>(ChunkKind::kKeyframe))
          throw Error(where + ": the step record after a scene chunk must be a keyframe");
        const uint64_t least = uint64_t{kPoseBytes} * static_cast<uint64_t>(info->scene_objects);
        if (c.raw_size < least)
          throw Error(where + ": its scene has " + std::to_string(info->scene_objects) +
                      " objects, whose poses take at least " + std::to_string(least) +
                      " bytes, but it holds " + std::to_string(c.raw_size));
        info->keyframe_due = false;
      }
      if (info->step_records == 0) info->first_step = c.step;
      info->last_step = c.step;
      ++info->step_records;
      break;
    case ChunkKind::kEnd: {
      const EndFields end = ParseEndJson(Decompress(stored, c.raw_size, where), where);
      info->ended = true;
      info->end_status = end.status;
      info->end_error = end.error;
      break;
    }
    case ChunkKind::kLinks:  // decoded by RecordingPlayer, with the step record before it
      if (info->step_records == 0 || c.step != static_cast<uint64_t>(info->last_step))
        throw Error(where + ": a links chunk that does not follow a step record of its step");
      break;
  }
}

// Reads the chunks of `file` after info->valid_size (ContinueScan).
void ScanChunks(const RecordingFile& file, RecordingInfo* info) {
  info->file_size = file.CurrentSize();
  uint64_t offset = info->valid_size;
  info->truncated = false;
  std::string head, stored;
  while (offset < info->file_size) {
    const size_t index = info->chunks.size();
    // A chunk the file ends inside: a run in progress, or killed.
    if (!file.ReadAt(offset, kChunkHeaderSize, &head)) {
      info->truncated = true;
      break;
    }
    const auto* h = reinterpret_cast<const uint8_t*>(head.data());
    const ChunkInfo c = ParseChunkHeader(h, offset);
    const std::string where = ChunkPlace(info->file, static_cast<int64_t>(index), c);
    if (std::memcmp(h, kMagic, 4) != 0) {
      if (offset == 0)
        throw Error(info->file.string() +
                    " is not a swarmsim recording (it does not start with SWRC)");
      throw Error(info->file.string() + " is corrupt: chunk " + std::to_string(index + 1) +
                  " at byte " + std::to_string(offset) + ": no chunk starts there (bad magic)");
    }
    if (index == 0 && c.kind != static_cast<uint8_t>(ChunkKind::kHeader))
      throw Error(info->file.string() +
                  " is not a swarmsim recording (its first chunk is no header)");
    // Sizes no writer makes: refused before anything is read for them.
    if (c.kind == 0) throw Error(where + ": its header is damaged (kind 0)");
    if (c.raw_size > kMaxChunkRawBytes || c.stored_size > ZSTD_compressBound(c.raw_size))
      throw Error(where + ": its header is damaged (" + std::to_string(c.stored_size) +
                  " bytes stored for " + std::to_string(c.raw_size) +
                  " decompressed; a chunk holds at most " +
                  std::to_string(kMaxChunkRawBytes >> 20) + " MiB decompressed)");
    if (!file.ReadAt(offset + kChunkHeaderSize, c.stored_size, &stored)) {
      info->truncated = true;
      break;
    }
    CheckChecksum(stored, c, where);
    // Unknown kinds (above 6) are skipped, as FORMAT.md says.
    if (c.kind <= static_cast<uint8_t>(ChunkKind::kLinks)) {
      try {
        CheckChunk(info, index, c, stored, where);
      } catch (const std::bad_alloc&) {
        throw Error(where + ": not enough memory to check it");
      }
    }
    info->chunks.push_back(c);
    offset += kChunkHeaderSize + c.stored_size;
    info->valid_size = offset;
  }
}

// The file `path` names: a run's folder's recording, or the file itself.
fs::path RecordingPath(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path file = path / kRecordingFileName;
    if (!fs::exists(fs::symlink_status(file, ec)))
      throw Error(path.string() + " has no " + kRecordingFileName +
                  ": record a run with swarmsim run WORLD --out " + path.string() + " --record");
    return file;
  }
  if (!fs::exists(fs::symlink_status(path, ec)))
    throw Error(path.string() +
                " does not exist: record a run with swarmsim run WORLD --out DIR "
                "--record");
  return path;
}

RecordingInfo Scan(const RecordingFile& file) {
  RecordingInfo info;
  info.file = file.path();
  ScanChunks(file, &info);
  if (info.chunks.empty())
    throw Error(info.file.string() +
                " holds no whole chunk yet (a run that just started, or not a recording)");
  return info;
}

}  // namespace

std::string RecordingInfo::Describe() const {
  std::ostringstream out;
  out << file.string() << ": format " << version_major << "." << version_minor << ", "
      << step_records << " step record" << (step_records == 1 ? "" : "s");
  if (step_records > 0) out << " (steps " << first_step << ".." << last_step << ")";
  out << ", " << SizeText(valid_size);
  if (ended) {
    out << "; the run ended (" << end_status;
    if (!end_error.empty()) out << ": " << end_error;
    out << ")";
  } else if (truncated) {
    out << "; the file ends inside a chunk at byte " << valid_size
        << " (a run in progress, or killed): read the " << step_records
        << " whole step records before it";
  } else {
    out << "; no end yet (a run in progress, or killed between steps)";
  }
  return out.str();
}

void ContinueScan(RecordingInfo* info) { ScanChunks(RecordingFile(info->file), info); }

RecordingInfo ScanRecording(const fs::path& path) {
  return Scan(RecordingFile(RecordingPath(path)));
}

std::string ReadChunk(const fs::path& file, const ChunkInfo& chunk) {
  return ReadPayload(RecordingFile(file), chunk, ChunkPlace(file, -1, chunk));
}

// --- RecordingPlayer ---------------------------------------------------------------

RecordingPlayer::RecordingPlayer(const fs::path& path)
    : file_(std::make_unique<RecordingFile>(RecordingPath(path))), info_(Scan(*file_)) {
  // The scan checked the header; its paint layer and metric names.
  const std::string where = ChunkPlace(info_.file, 0, info_.chunks[0]);
  HeaderFields header = ParseHeaderJson(info_.header_json, where);
  if (header.has_paint) {
    const size_t cells = size_t{header.paint_width} * header.paint_height;  // <= kMaxPaintCells
    try {
      paint_.resize(3 * cells);
    } catch (const std::bad_alloc&) {
      throw Error(where + ": not enough memory for its paint layer of " + std::to_string(cells) +
                  " cells");
    }
    for (int c = 0; c < 3; ++c)
      paint_background_[c] = static_cast<uint8_t>(std::lround(header.paint_background[c] * 255));
    for (size_t i = 0; i < paint_.size(); ++i) paint_[i] = paint_background_[i % 3];
  }
  metric_names_ = std::move(header.metrics);
}

RecordingPlayer::~RecordingPlayer() = default;

void RecordingPlayer::Refresh() { ScanChunks(*file_, &info_); }

// The scene's robots and count; the arrays by id wait for its keyframe.
void RecordingPlayer::LoadScene(std::string text, const std::string& where) {
  const SceneFields scene = ParseSceneJson(text, where);
  scene_json_ = std::move(text);
  scene_objects_ = scene.object_count;
  scene_ranges_.clear();
  robot_roots_.clear();
  for (const SceneRobot& robot : scene.robots) {
    scene_ranges_.emplace_back(robot.first, robot.count);
    robot_roots_.emplace_back(robot.index, static_cast<int64_t>(robot.first));
  }
  std::sort(robot_roots_.begin(), robot_roots_.end());
  keyframe_due_ = true;
}

int64_t RecordingPlayer::robot_root(int robot_index) const {
  const std::pair<int64_t, int64_t> key{robot_index, std::numeric_limits<int64_t>::min()};
  const auto it = std::lower_bound(robot_roots_.begin(), robot_roots_.end(), key);
  return it != robot_roots_.end() && it->first == robot_index ? it->second : -1;
}

bool RecordingPlayer::Next() {
  while (next_chunk_ < info_.chunks.size()) {
    const size_t index = next_chunk_++;
    const ChunkInfo& c = info_.chunks[index];
    const auto kind = static_cast<ChunkKind>(c.kind);
    if (kind != ChunkKind::kScene && kind != ChunkKind::kKeyframe && kind != ChunkKind::kDelta)
      continue;
    const std::string where = ChunkPlace(info_.file, static_cast<int64_t>(index), c);
    try {
      if (kind == ChunkKind::kScene) {
        LoadScene(ReadPayload(*file_, c, where), where);
        continue;
      }
      if (scene_json_.empty()) throw Error(where + ": a step record before any scene chunk");
      Decode(ReadPayload(*file_, c, where), kind == ChunkKind::kKeyframe, where);
      // Its links, if the links chunk of its step follows it.
      links_.clear();
      if (next_chunk_ < info_.chunks.size() &&
          info_.chunks[next_chunk_].kind == static_cast<uint8_t>(ChunkKind::kLinks) &&
          info_.chunks[next_chunk_].step == c.step) {
        const size_t links = next_chunk_++;
        const std::string links_where =
            ChunkPlace(info_.file, static_cast<int64_t>(links), info_.chunks[links]);
        DecodeLinks(ReadPayload(*file_, info_.chunks[links], links_where), links_where);
      }
    } catch (const std::bad_alloc&) {
      throw Error(where + ": not enough memory to read it");
    }
    step_ = c.step;
    return true;
  }
  return false;
}

bool RecordingPlayer::SeekTo(int64_t step) {
  // The last keyframe at or before `step`.
  size_t keyframe = info_.chunks.size();
  for (size_t i = 0; i < info_.chunks.size(); ++i) {
    const ChunkInfo& c = info_.chunks[i];
    if (c.kind == static_cast<uint8_t>(ChunkKind::kKeyframe) && c.step <= step) keyframe = i;
    if ((c.kind == static_cast<uint8_t>(ChunkKind::kKeyframe) ||
         c.kind == static_cast<uint8_t>(ChunkKind::kDelta)) &&
        c.step > step)
      break;
  }
  if (keyframe == info_.chunks.size()) return false;
  // The scene in force at the keyframe (the last scene chunk before it),
  // then the keyframe and the deltas after it.
  size_t scene = info_.chunks.size();
  for (size_t i = keyframe; i-- > 0;)
    if (info_.chunks[i].kind == static_cast<uint8_t>(ChunkKind::kScene)) {
      scene = i;
      break;
    }
  if (scene == info_.chunks.size()) return false;  // the scan refuses such files
  const std::string where =
      ChunkPlace(info_.file, static_cast<int64_t>(scene), info_.chunks[scene]);
  try {
    LoadScene(ReadPayload(*file_, info_.chunks[scene], where), where);
  } catch (const std::bad_alloc&) {
    throw Error(where + ": not enough memory to read it");
  }
  next_chunk_ = keyframe;
  while (Next())
    if (step_ >= step) return step_ == step;
  return false;
}

Pose RecordingPlayer::frame_pose(uint32_t id) const {
  const Quantized& q = pose_.at(id);
  Pose X;
  X.p = {q.x * kPositionUnit, q.y * kPositionUnit, q.z * kPositionUnit};
  X.q = {q.qw / kQuaternionScale, q.qx / kQuaternionScale, q.qy / kQuaternionScale,
         q.qz / kQuaternionScale};
  const double norm = std::sqrt(X.q.w * X.q.w + X.q.x * X.q.x + X.q.y * X.q.y + X.q.z * X.q.z);
  if (norm > 0) X.q = {X.q.w / norm, X.q.x / norm, X.q.y / norm, X.q.z / norm};
  return X;
}

Pose RecordingPlayer::world_pose(uint32_t id) const {
  const int64_t root = root_.at(id);
  return root < 0 ? frame_pose(id) : frame_pose(static_cast<uint32_t>(root)) * frame_pose(id);
}

// A links chunk (FORMAT.md "Links chunk"): every id checked against the
// scene in force, every count against the bytes left.
void RecordingPlayer::DecodeLinks(const std::string& payload, const std::string& where) {
  const auto* data = reinterpret_cast<const uint8_t*>(payload.data());
  const auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, data + at, 4);
    return v;
  };
  if (payload.size() < 8) throw Error(where + ": a links chunk shorter than its counts");
  const uint64_t n = u32(4);
  if (payload.size() != 8 + 8 * n)
    throw Error(where + ": a links chunk of " + std::to_string(n) + " links holds " +
                std::to_string(payload.size()) + " bytes, not " + std::to_string(8 + 8 * n));
  links_.resize(n);
  uint64_t from = 0;
  for (uint64_t i = 0; i < n; ++i) {
    from += u32(8 + 4 * i);
    const uint32_t to = u32(8 + 4 * n + 4 * i);
    if (from >= pose_.size() || to >= pose_.size())
      throw Error(where + ": link " + std::to_string(i) + " names an object past the scene's " +
                  std::to_string(pose_.size()));
    links_[i] = {static_cast<uint32_t>(from), to};
  }
}

// A step record (FORMAT.md "Step records"). Every count is checked against
// the bytes left before anything is allocated for it, every id against the
// scene.
void RecordingPlayer::Decode(const std::string& payload, bool keyframe, const std::string& where) {
  const auto* data = reinterpret_cast<const uint8_t*>(payload.data());
  size_t at = 0;     // <= payload.size()
  samples_.clear();  // their names view metric_names_, which changes below
  const auto fail = [&](const std::string& what) {
    throw Error(where + ": its step record does not decode at byte " + std::to_string(at) + " of " +
                std::to_string(payload.size()) + ": " + what);
  };
  const auto need = [&](uint64_t bytes) {
    if (bytes > payload.size() - at) fail("it ends early");
  };
  const auto get = [&]<typename T>(T* out) {
    need(sizeof(T));
    std::memcpy(out, data + at, sizeof(T));
    at += sizeof(T);
  };
  const auto pad = [&](size_t alignment) {
    const size_t to = (at + alignment - 1) / alignment * alignment;
    need(to - at);
    at = to;
  };
  // `n` ascending ids below `limit` (of `unit`s), as differences;
  // `bytes_each`: what the section holds per id, all of which must be there.
  const auto ids = [&](uint32_t n, uint64_t limit, size_t bytes_each, const std::string& what,
                       const char* unit) {
    need(uint64_t{n} * bytes_each);
    std::vector<uint32_t> out(n);
    uint64_t id = 0;
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t d = 0;
      get(&d);
      if (i > 0 && d == 0) fail(what + " ids are not ascending");
      id = (i == 0 ? 0 : id) + d;
      if (id >= limit)
        fail(what + " id " + std::to_string(id) + " is outside the " + std::to_string(limit) + " " +
             unit + " of the scene in force");
      out[i] = static_cast<uint32_t>(id);
    }
    return out;
  };
  uint32_t n = 0, pad32 = 0, record = 0;
  get(&time_);
  get(&record);
  get(&pad32);
  // Poses. The keyframe after a scene chunk lists every object: the arrays
  // by id are made for it only once its bytes are known to be there.
  get(&n);
  if (keyframe_due_ && !keyframe) fail("a delta right after a scene chunk (a keyframe must come)");
  if (keyframe && n != scene_objects_)
    fail("a keyframe lists " + std::to_string(n) + " poses, but its scene has " +
         std::to_string(scene_objects_) + " objects");
  need(uint64_t{n} * kPoseBytes);
  if (keyframe_due_) {
    root_.assign(scene_objects_, -1);
    for (const auto& [first, count] : scene_ranges_)
      for (uint64_t id = first + 1; id < first + count; ++id)
        root_[id] = static_cast<int64_t>(first);
    pose_.assign(scene_objects_, {});
    color_.assign(scene_objects_, 0);
    reading_.assign(scene_objects_, 0);
    keyframe_due_ = false;
  }
  const std::vector<uint32_t> pose_ids = ids(n, pose_.size(), kPoseBytes, "pose", "objects");
  const auto apply = [&]<typename T>(T Quantized::*field) {
    for (const uint32_t id : pose_ids) {
      T v{};
      get(&v);
      using U = std::make_unsigned_t<T>;
      pose_[id].*field = keyframe ? v
                                  : static_cast<T>(static_cast<U>(static_cast<U>(pose_[id].*field) +
                                                                  static_cast<U>(v)));
    }
  };
  apply(&Quantized::x);
  apply(&Quantized::y);
  apply(&Quantized::z);
  apply(&Quantized::qw);
  apply(&Quantized::qx);
  apply(&Quantized::qy);
  apply(&Quantized::qz);
  pad(4);
  // Colours.
  get(&n);
  for (const uint32_t id : ids(n, color_.size(), 8, "colour", "objects")) get(&color_[id]);
  // Proximity readings.
  get(&n);
  for (const uint32_t id : ids(n, reading_.size(), 6, "proximity reading", "objects"))
    get(&reading_[id]);
  pad(4);
  // Paint cells.
  get(&n);
  if (n > 0 && paint_.empty()) fail("paint cells, but the header has no paint layer");
  if (keyframe)
    for (size_t i = 0; i < paint_.size(); ++i) paint_[i] = paint_background_[i % 3];
  for (const uint32_t cell : ids(n, paint_.size() / 3, 8, "paint cell", "cells")) {
    uint32_t rgba = 0;
    get(&rgba);
    paint_[3 * size_t{cell}] = rgba & 0xff;
    paint_[3 * size_t{cell} + 1] = (rgba >> 8) & 0xff;
    paint_[3 * size_t{cell} + 2] = (rgba >> 16) & 0xff;
  }
  // Metrics.
  uint32_t first_name = 0, name_count = 0;
  get(&first_name);
  get(&name_count);
  if (first_name > metric_names_.size())
    fail("metric names from id " + std::to_string(first_name) + ", but " +
         std::to_string(metric_names_.size()) + " are known");
  metric_names_.resize(first_name);
  need(uint64_t{name_count} * 2);
  for (uint32_t i = 0; i < name_count; ++i) {
    uint16_t length = 0;
    get(&length);
    need(length);
    metric_names_.emplace_back(payload.data() + at, length);
    at += length;
  }
  pad(4);
  get(&n);
  need(uint64_t{n} * 20);  // name id, robot, step, value
  samples_.assign(n, {});
  for (RecordedSample& s : samples_) {
    uint32_t name = 0;
    get(&name);
    if (name >= metric_names_.size())
      fail("metric name id " + std::to_string(name) + ", but " +
           std::to_string(metric_names_.size()) + " are known");
    s.name = metric_names_[name];
  }
  for (RecordedSample& s : samples_) {
    int32_t robot = 0;
    get(&robot);
    s.robot = robot;
  }
  for (RecordedSample& s : samples_) {
    uint32_t step = 0;
    get(&step);
    s.step = step;
  }
  pad(8);
  for (RecordedSample& s : samples_) get(&s.value);
  if (at != payload.size()) fail(std::to_string(payload.size() - at) + " bytes left over");
}

}  // namespace swarmsim::record
