#include "swarm/record/reader.h"

#include <xxhash.h>
#include <zstd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "framework/error.h"
#include "swarm/record/format.h"

namespace swarmsim::record {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Chunks bigger than this are taken for a corrupt header, not a long payload.
constexpr uint32_t kMaxChunkBytes = uint32_t{1} << 30;

uint32_t Get32(const uint8_t* p) {
  return p[0] | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

std::string Megabytes(uint64_t bytes) {
  std::ostringstream out;
  out.precision(bytes < 10'000'000 ? 2 : 3);
  out << static_cast<double>(bytes) / 1e6 << " MB";
  return out.str();
}

std::string Decompress(const std::string& stored, uint32_t raw_size, const std::string& where) {
  std::string raw(raw_size, '\0');
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), stored.data(), stored.size());
  if (ZSTD_isError(n))
    throw Error(where + ": the payload does not decompress (" + ZSTD_getErrorName(n) + ")");
  if (n != raw_size)
    throw Error(where + ": the payload decompresses to " + std::to_string(n) + " bytes, not " +
                std::to_string(raw_size));
  return raw;
}

std::string ChunkWhere(const RecordingInfo& info, size_t index, uint64_t offset) {
  return info.file.string() + " is corrupt: chunk " + std::to_string(index + 1) + " at byte " +
         std::to_string(offset);
}

// The header chunk's JSON: format name and version.
void CheckHeader(RecordingInfo* info, const std::string& text) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception&) {
    throw Error(info->file.string() + " is corrupt: its header is not JSON");
  }
  if (!j.is_object() || j.value("format", "") != kFormatName || !j.contains("version") ||
      !j["version"].is_array() || j["version"].size() < 2 || !j["version"][0].is_number_integer())
    throw Error(info->file.string() + " is not a swarmsim recording (its header names no " +
                kFormatName + " version)");
  info->version_major = j["version"][0].get<int>();
  info->version_minor = j["version"][1].is_number_integer() ? j["version"][1].get<int>() : 0;
  if (info->version_major > kVersionMajor)
    throw Error(info->file.string() + " is a recording of format version " +
                std::to_string(info->version_major) + "." + std::to_string(info->version_minor) +
                ", newer than this swarmsim reads (" + std::to_string(kVersionMajor) + "." +
                std::to_string(kVersionMinor) + "): use a newer swarmsim");
  info->header_json = text;
}

}  // namespace

std::string RecordingInfo::Describe() const {
  std::ostringstream out;
  out << file.string() << ": format " << version_major << "." << version_minor << ", "
      << step_records << " step record" << (step_records == 1 ? "" : "s");
  if (step_records > 0) out << " (steps " << first_step << ".." << last_step << ")";
  out << ", " << Megabytes(valid_size);
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

void ContinueScan(RecordingInfo* info) {
  std::ifstream in(info->file, std::ios::binary);
  if (!in) throw Error("cannot read " + info->file.string());
  in.seekg(0, std::ios::end);
  info->file_size = static_cast<uint64_t>(in.tellg());
  uint64_t offset = info->valid_size;
  info->truncated = false;
  std::string stored;
  while (offset < info->file_size) {
    const size_t index = info->chunks.size();
    if (info->file_size - offset < kChunkHeaderSize) {
      info->truncated = true;
      break;
    }
    uint8_t h[kChunkHeaderSize];
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(h), kChunkHeaderSize);
    if (!in) throw Error("cannot read " + info->file.string());
    if (std::memcmp(h, kMagic, 4) != 0) {
      if (offset == 0)
        throw Error(info->file.string() +
                    " is not a swarmsim recording (it does not start with SWRC)");
      throw Error(ChunkWhere(*info, index, offset) + ": no chunk starts there (bad magic)");
    }
    ChunkInfo c;
    c.offset = offset;
    c.kind = h[4];
    c.step = Get32(h + 8);
    c.stored_size = Get32(h + 12);
    c.raw_size = Get32(h + 16);
    if (c.kind == 0 || c.stored_size > kMaxChunkBytes || c.raw_size > kMaxChunkBytes)
      throw Error(ChunkWhere(*info, index, offset) + ": its header is damaged");
    if (index == 0 && c.kind != static_cast<uint8_t>(ChunkKind::kHeader))
      throw Error(info->file.string() +
                  " is not a swarmsim recording (its first chunk is no header)");
    if (info->file_size - offset - kChunkHeaderSize < c.stored_size) {
      info->truncated = true;
      break;
    }
    stored.resize(c.stored_size);
    in.read(stored.data(), c.stored_size);
    if (!in) throw Error("cannot read " + info->file.string());
    const uint32_t sum = XXH32(stored.data(), stored.size(), 0);
    if (sum != Get32(h + 20)) {
      std::ostringstream message;
      message << ChunkWhere(*info, index, offset) << ": checksum mismatch (stored 0x" << std::hex
              << Get32(h + 20) << ", computed 0x" << sum << ")";
      throw Error(message.str());
    }
    const auto kind = static_cast<ChunkKind>(c.kind);
    if (kind == ChunkKind::kHeader) {
      if (index != 0) throw Error(ChunkWhere(*info, index, offset) + ": a second header chunk");
      CheckHeader(info, Decompress(stored, c.raw_size, ChunkWhere(*info, index, offset)));
    } else if (kind == ChunkKind::kKeyframe || kind == ChunkKind::kDelta) {
      if (info->step_records == 0) info->first_step = c.step;
      info->last_step = c.step;
      ++info->step_records;
    } else if (kind == ChunkKind::kEnd) {
      const std::string text = Decompress(stored, c.raw_size, ChunkWhere(*info, index, offset));
      const json j = json::parse(text, nullptr, false);
      info->ended = true;
      if (j.is_object()) {
        info->end_status = j.value("status", "");
        info->end_error = j.value("error", "");
      }
    }
    info->chunks.push_back(c);
    offset += kChunkHeaderSize + c.stored_size;
    info->valid_size = offset;
  }
}

RecordingInfo ScanRecording(const fs::path& path) {
  RecordingInfo info;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    info.file = path / kRecordingFileName;
    if (!fs::exists(info.file, ec))
      throw Error(path.string() + " has no " + kRecordingFileName +
                  ": record a run with swarmsim run WORLD --out " + path.string() + " --record");
  } else {
    info.file = path;
    if (!fs::exists(path, ec))
      throw Error(path.string() +
                  " does not exist: record a run with swarmsim run WORLD --out DIR "
                  "--record");
  }
  ContinueScan(&info);
  if (info.chunks.empty())
    throw Error(info.file.string() +
                " holds no whole chunk yet (a run that just started, or not a recording)");
  return info;
}

std::string ReadChunk(const fs::path& file, const ChunkInfo& chunk) {
  std::ifstream in(file, std::ios::binary);
  std::string stored(chunk.stored_size, '\0');
  in.seekg(static_cast<std::streamoff>(chunk.offset + kChunkHeaderSize));
  in.read(stored.data(), chunk.stored_size);
  const std::string where = file.string() + ": chunk at byte " + std::to_string(chunk.offset);
  if (!in) throw Error(where + ": cannot read it");
  return Decompress(stored, chunk.raw_size, where);
}

// --- RecordingPlayer ---------------------------------------------------------------

RecordingPlayer::RecordingPlayer(const fs::path& path) : info_(ScanRecording(path)) {
  const json header = json::parse(info_.header_json);
  if (const json& paint = header["paint"]; paint.is_object()) {
    const int w = paint["width"].get<int>(), h = paint["height"].get<int>();
    paint_.resize(static_cast<size_t>(w) * h * 3);
    for (int c = 0; c < 3; ++c)
      paint_background_[c] =
          static_cast<uint8_t>(std::lround(paint["background"][c].get<double>() * 255));
    for (size_t i = 0; i < paint_.size(); ++i) paint_[i] = paint_background_[i % 3];
  }
  for (const json& name : header["metrics"]) metric_names_.push_back(name.get<std::string>());
}

RecordingPlayer::~RecordingPlayer() = default;

void RecordingPlayer::LoadScene(const std::string& text) {
  scene_json_ = text;
  const json scene = json::parse(text);
  const size_t n = scene["object_count"].get<size_t>();
  root_.assign(n, -1);
  robot_roots_.clear();
  for (const json& robot : scene["robots"]) {
    const int64_t first = robot["first"].get<int64_t>(), count = robot["count"].get<int64_t>();
    for (int64_t id = first + 1; id < first + count; ++id) root_[id] = first;
    const size_t index = robot["index"].get<size_t>();
    if (robot_roots_.size() <= index) robot_roots_.resize(index + 1, -1);
    robot_roots_[index] = first;
  }
  pose_.assign(n, {});
  color_.assign(n, 0);
  reading_.assign(n, 0);
}

int64_t RecordingPlayer::robot_root(int robot_index) const {
  return robot_index >= 0 && static_cast<size_t>(robot_index) < robot_roots_.size()
             ? robot_roots_[robot_index]
             : -1;
}

bool RecordingPlayer::Next() {
  while (next_chunk_ < info_.chunks.size()) {
    const ChunkInfo& c = info_.chunks[next_chunk_++];
    const auto kind = static_cast<ChunkKind>(c.kind);
    if (kind == ChunkKind::kScene) {
      LoadScene(ReadChunk(info_.file, c));
    } else if (kind == ChunkKind::kKeyframe || kind == ChunkKind::kDelta) {
      if (scene_json_.empty())
        throw Error(info_.file.string() + ": a step record at byte " + std::to_string(c.offset) +
                    " comes before any scene chunk");
      Decode(ReadChunk(info_.file, c), kind == ChunkKind::kKeyframe);
      step_ = c.step;
      return true;
    }
  }
  return false;
}

bool RecordingPlayer::SeekTo(int64_t step) {
  // The last keyframe at or before `step`, and the scene chunk before it.
  size_t keyframe = info_.chunks.size(), scene = info_.chunks.size();
  for (size_t i = 0; i < info_.chunks.size(); ++i) {
    const ChunkInfo& c = info_.chunks[i];
    if (c.kind == static_cast<uint8_t>(ChunkKind::kScene)) scene = i;
    if (c.kind == static_cast<uint8_t>(ChunkKind::kKeyframe) && c.step <= step) keyframe = i;
    if ((c.kind == static_cast<uint8_t>(ChunkKind::kKeyframe) ||
         c.kind == static_cast<uint8_t>(ChunkKind::kDelta)) &&
        c.step > step)
      break;
  }
  if (keyframe == info_.chunks.size()) return false;
  // The scene in force at the keyframe: the last scene chunk before it.
  for (size_t i = keyframe; i-- > 0;)
    if (info_.chunks[i].kind == static_cast<uint8_t>(ChunkKind::kScene)) {
      scene = i;
      break;
    }
  next_chunk_ = scene;
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

// A step record (FORMAT.md "Step records").
void RecordingPlayer::Decode(const std::string& payload, bool keyframe) {
  const auto* data = reinterpret_cast<const uint8_t*>(payload.data());
  size_t at = 0;
  const auto fail = [&](const std::string& what) {
    throw Error(info_.file.string() + ": a step record does not decode (" + what + ")");
  };
  const auto need = [&](size_t bytes) {
    if (payload.size() - at < bytes || at > payload.size()) fail("it ends early");
  };
  const auto get = [&]<typename T>(T* out) {
    need(sizeof(T));
    std::memcpy(out, data + at, sizeof(T));
    at += sizeof(T);
  };
  const auto pad = [&](size_t alignment) { at = (at + alignment - 1) / alignment * alignment; };
  const auto ids = [&](uint32_t n, uint32_t limit) {
    std::vector<uint32_t> out(n);
    uint32_t last = 0;
    for (uint32_t& id : out) {
      uint32_t d = 0;
      get(&d);
      id = last + d;
      last = id;
      if (id >= limit) fail("an id out of range");
    }
    return out;
  };
  uint32_t n = 0, pad32 = 0, record = 0;
  get(&time_);
  get(&record);
  get(&pad32);
  // Poses.
  get(&n);
  const std::vector<uint32_t> pose_ids = ids(n, static_cast<uint32_t>(pose_.size()));
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
  for (const uint32_t id : ids(n, static_cast<uint32_t>(color_.size()))) get(&color_[id]);
  // Proximity readings.
  get(&n);
  for (const uint32_t id : ids(n, static_cast<uint32_t>(reading_.size()))) get(&reading_[id]);
  pad(4);
  // Paint cells.
  get(&n);
  if (keyframe && n > 0 && paint_.empty()) fail("paint cells without a paint layer");
  if (keyframe)
    for (size_t i = 0; i < paint_.size(); ++i) paint_[i] = paint_background_[i % 3];
  for (const uint32_t cell : ids(n, static_cast<uint32_t>(paint_.size() / 3))) {
    uint32_t rgba = 0;
    get(&rgba);
    paint_[3 * cell] = rgba & 0xff;
    paint_[3 * cell + 1] = (rgba >> 8) & 0xff;
    paint_[3 * cell + 2] = (rgba >> 16) & 0xff;
  }
  // Metrics.
  uint32_t first_name = 0, name_count = 0;
  get(&first_name);
  get(&name_count);
  if (first_name > metric_names_.size()) fail("a metric name id out of order");
  metric_names_.resize(first_name);
  for (uint32_t i = 0; i < name_count; ++i) {
    uint16_t length = 0;
    get(&length);
    need(length);
    metric_names_.emplace_back(payload.data() + at, length);
    at += length;
  }
  pad(4);
  get(&n);
  samples_.assign(n, {});
  for (RecordedSample& s : samples_) {
    uint32_t name = 0;
    get(&name);
    if (name >= metric_names_.size()) fail("an unknown metric name id");
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
  if (at != payload.size()) fail("bytes left over");
}

}  // namespace swarmsim::record
