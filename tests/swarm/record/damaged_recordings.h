// Damaged recordings made from a good one, for the tests of the readers'
// bounds (chunk_json, chunk_reader, reader; issue 26): chunks taken apart,
// changed and put together again, and what reading them says.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "swarm/record/writer.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::record::damaged {

namespace fs = std::filesystem;
using nlohmann::json;

inline const fs::path kDiffusion =
    fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/recordings/diffusion/recording.swrec";

// A recording's chunks, decompressed.
struct Chunk {
  uint8_t kind = 0;
  uint32_t step = 0;
  std::string payload;
};

inline std::vector<Chunk> ChunksOf(const fs::path& file) {
  const RecordingInfo info = ScanRecording(file);
  std::vector<Chunk> chunks;
  for (const ChunkInfo& c : info.chunks) chunks.push_back({c.kind, c.step, ReadChunk(file, c)});
  return chunks;
}

inline std::string Encode(const std::vector<Chunk>& chunks) {
  std::string bytes;
  for (const Chunk& c : chunks) bytes += EncodeChunk(c.kind, c.step, c.payload);
  return bytes;
}

// A run folder `name` holding `bytes` as its recording.
inline fs::path WriteRun(const std::string& name, const std::string& bytes) {
  const fs::path dir = swarmsim::testing::FreshTempDir("recording_bounds", name);
  fs::create_directories(dir);
  std::ofstream(dir / kRecordingFileName, std::ios::binary) << bytes;
  return dir;
}

// The diffusion recording with its scene chunk's JSON changed by `change`.
inline std::string WithScene(const std::function<void(json&)>& change) {
  std::vector<Chunk> chunks = ChunksOf(kDiffusion);
  for (Chunk& c : chunks)
    if (c.kind == static_cast<uint8_t>(ChunkKind::kScene)) {
      json scene = json::parse(c.payload);
      change(scene);
      c.payload = scene.dump();
    }
  return Encode(chunks);
}

// What reading the whole recording in `dir` says ("" when it reads).
inline std::string ReadError(const fs::path& dir) {
  try {
    RecordingPlayer player(dir);
    while (player.Next()) {
    }
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A message a user can act on: the file, a byte offset, no library's text.
inline void ExpectUsersMessage(const std::string& error, const fs::path& dir) {
  EXPECT_NE(error.find((dir / kRecordingFileName).string()), std::string::npos) << error;
  EXPECT_NE(error.find(" at byte "), std::string::npos) << error;
  EXPECT_EQ(error.find("json.exception"), std::string::npos) << error;
  EXPECT_EQ(error.find("bad_alloc"), std::string::npos) << error;
}

// A step record's payload, section by section (FORMAT.md "Step records").
class StepRecord {
 public:
  template <typename T>
  StepRecord& Put(T value) {
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
    return *this;
  }
  StepRecord& Pad(size_t alignment) {
    while (bytes_.size() % alignment != 0) bytes_ += '\0';
    return *this;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// A recording of one robot of one object: header, scene, and a keyframe
// whose counts are `poses`, `colours`, `readings`, `cells`, `names` and
// `samples` (the sections themselves as for one pose and nothing else).
inline std::string OneObjectRecording(uint32_t poses, uint32_t colours, uint32_t readings,
                                      uint32_t cells, uint32_t names, uint32_t samples) {
  StepRecord s;
  s.Put<double>(0).Put<uint32_t>(0).Put<uint32_t>(0);
  s.Put<uint32_t>(poses).Put<uint32_t>(0);  // id 0
  for (int i = 0; i < 3; ++i) s.Put<int32_t>(0);
  s.Put<int16_t>(32767).Put<int16_t>(0).Put<int16_t>(0).Put<int16_t>(0).Pad(4);
  s.Put<uint32_t>(colours).Put<uint32_t>(readings).Pad(4).Put<uint32_t>(cells);
  s.Put<uint32_t>(0).Put<uint32_t>(names).Pad(4).Put<uint32_t>(samples).Pad(8);
  return EncodeChunk(1, 0,
                     R"({"format": "swarmsim-recording", "version": [1, 0], "metrics": []})") +
         EncodeChunk(2, 0,
                     R"({"object_count": 1, "templates": [{"objects": [{"parent": -1}]}],
                         "robots": [{"index": 0, "first": 0, "count": 1, "template": 0}],
                         "objects": [], "meshes": []})") +
         EncodeChunk(3, 0, s.bytes());
}

// Sets a u32 field of the chunk header at `chunk_offset` (12: stored size, 16: raw size).
inline void SetHeaderField(std::string* bytes, uint64_t chunk_offset, int field_offset,
                           uint32_t value) {
  std::memcpy(bytes->data() + chunk_offset + field_offset, &value, 4);
}

// --- The program -------------------------------------------------------------------

// `swarmsim ARGS`, given at most a minute (a hang fails instead of blocking
// the suite); `limit_kb`: its address space, if not 0.
inline swarmsim::testing::CommandResult Swarmsim(const std::string& args, int limit_kb = 0) {
  std::string command = "timeout 60 " + std::string(SWARMSIM_BINARY) + " " + args;
  if (limit_kb > 0) command = swarmsim::testing::AddressSpaceLimit(limit_kb) + command;
  return swarmsim::testing::RunCommand(command);
}

}  // namespace swarmsim::record::damaged
