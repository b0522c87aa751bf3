// Damaged recordings as a user meets them: record-info, view and view
// --export refuse them alike, with a message naming the file, the chunk and
// its byte offset, and never crash, hang, or allocate what a damaged field
// claims (issue 26).
#include <gtest/gtest.h>
#include <sys/stat.h>

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

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::FreshTempDir;
using testing::RunCommand;

const fs::path kDiffusion =
    fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/recordings/diffusion/recording.swrec";

// A recording's chunks, decompressed.
struct Chunk {
  uint8_t kind = 0;
  uint32_t step = 0;
  std::string payload;
};

std::vector<Chunk> ChunksOf(const fs::path& file) {
  const RecordingInfo info = ScanRecording(file);
  std::vector<Chunk> chunks;
  for (const ChunkInfo& c : info.chunks) chunks.push_back({c.kind, c.step, ReadChunk(file, c)});
  return chunks;
}

std::string Encode(const std::vector<Chunk>& chunks) {
  std::string bytes;
  for (const Chunk& c : chunks) bytes += EncodeChunk(c.kind, c.step, c.payload);
  return bytes;
}

// A run folder `name` holding `bytes` as its recording.
fs::path WriteRun(const std::string& name, const std::string& bytes) {
  const fs::path dir = FreshTempDir("recording_bounds", name);
  fs::create_directories(dir);
  std::ofstream(dir / kRecordingFileName, std::ios::binary) << bytes;
  return dir;
}

// The diffusion recording with its scene chunk's JSON changed by `change`.
std::string WithScene(const std::function<void(json&)>& change) {
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
std::string ReadError(const fs::path& dir) {
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
void ExpectUsersMessage(const std::string& error, const fs::path& dir) {
  EXPECT_NE(error.find((dir / kRecordingFileName).string()), std::string::npos) << error;
  EXPECT_NE(error.find(" at byte "), std::string::npos) << error;
  EXPECT_EQ(error.find("json.exception"), std::string::npos) << error;
  EXPECT_EQ(error.find("bad_alloc"), std::string::npos) << error;
}

TEST(RecordingBoundsTest, SceneIndicesAreCheckedAgainstTheScene) {
  struct Case {
    const char* name;
    std::function<void(json&)> change;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"first", [](json& s) { s["robots"][0]["first"] = 1000000; },
       "robots[0].first is 1000000 and its count 27: ids outside the scene's 274 objects"},
      {"count", [](json& s) { s["robots"][0]["count"] = 1000000; },
       "robots[0].count is 1000000, but its template 0 has 27 objects"},
      {"object_count", [](json& s) { s["object_count"] = 1000000000000; },
       "object_count is 1000000000000, more than the"},
      {"object_count_more", [](json& s) { s["object_count"] = 275; },
       "object_count is 275, but its robots and objects have 274 ids"},
      {"template", [](json& s) { s["robots"][0]["template"] = 3; },
       "robots[0].template is 3, but the scene has 1 templates"},
      {"overlap", [](json& s) { s["robots"][1]["first"] = 0; }, "claims id 0, as does robots["},
      {"object_id_twice", [](json& s) { s["objects"][0]["id"] = 5; }, "claims id 5, as does"},
      {"object_id", [](json& s) { s["objects"][0]["id"] = 274; },
       "objects[0].id is 274, outside the scene's 274 objects"},
      {"object_parent", [](json& s) { s["objects"][0]["parent"] = 1000; },
       "objects[0].parent is 1000, outside the scene's 274 objects"},
      {"template_parent", [](json& s) { s["templates"][0]["objects"][1]["parent"] = 5; },
       "templates[0].objects[1].parent is 5, expected a whole number from -1 to 0"},
      {"index_twice", [](json& s) { s["robots"][2]["index"] = 1; }, "two robots have the index 1"},
      {"negative_first", [](json& s) { s["robots"][0]["first"] = -1; },
       "robots[0].first is -1, expected a whole number from 0 up"},
      {"fraction", [](json& s) { s["robots"][0]["first"] = 1.5; }, "robots[0].first is 1.5"},
      {"no_first", [](json& s) { s["robots"][0].erase("first"); }, "robots[0] has no first"},
      {"robots_map", [](json& s) { s["robots"] = json::object(); },
       "robots is a map, expected a list"},
      {"count_text", [](json& s) { s["object_count"] = "many"; },
       "object_count is \"many\", expected a whole number"},
      {"mesh", [](json& s) { s["objects"][0]["mesh"] = 0; },
       "objects[0].mesh is 0, but the scene has 0 meshes"},
      {"triangles",
       [](json& s) {
         s["meshes"] = json::array({{{"vertices", {0, 0, 0}}, {"triangles", {0, 0, 1}}}});
       },
       "meshes[0].triangles names vertex 1, but it has 1 vertices"},
      {"deep",
       [](json& s) {
         json deep = json::array();
         for (int i = 0; i < 100; ++i) deep = json::array({deep});
         s["robots"][0]["parameters"]["x"] = deep;
       },
       "is nested deeper than 64 levels"},
  };
  for (const Case& c : cases) {
    const fs::path dir = WriteRun(c.name, WithScene(c.change));
    const std::string prefix =
        (dir / kRecordingFileName).string() + " is corrupt: chunk 2 at byte 332 (scene): ";
    std::string error;
    try {
      ScanRecording(dir);
    } catch (const Error& e) {
      error = e.what();
    }
    EXPECT_EQ(error.rfind(prefix, 0), 0u) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
    EXPECT_EQ(ReadError(dir), error) << c.name;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
}

TEST(RecordingBoundsTest, BrokenJsonAndWrongTypesAreNamedInWords) {
  // Header, scene and end chunks whose JSON is broken or of the wrong type.
  std::vector<Chunk> original = ChunksOf(kDiffusion);
  const auto with = [&](size_t index, std::string payload) {
    std::vector<Chunk> chunks = original;
    chunks[index].payload = std::move(payload);
    return Encode(chunks);
  };
  json header = json::parse(original[0].payload);
  const size_t end = original.size() - 1;
  ASSERT_EQ(original[end].kind, static_cast<uint8_t>(ChunkKind::kEnd));
  struct Case {
    const char* name;
    std::string bytes;
    std::string expected;
  };
  std::vector<Case> cases;
  json paint = header;
  paint["paint"] = {{"width", "x"}, {"height", 10}};
  cases.push_back({"paint_width", with(0, paint.dump()),
                   "(header): paint.width is \"x\", expected a whole number from 1"});
  paint["paint"] = {{"width", 100000}, {"height", 100000}};
  cases.push_back({"paint_size", with(0, paint.dump()),
                   "(header): paint is 100000 x 100000 cells, more than the 67108864"});
  json metrics = header;
  metrics["metrics"] = {1, 2};
  cases.push_back(
      {"metrics", with(0, metrics.dump()), "(header): metrics[0] is 1, expected a metric's name"});
  cases.push_back({"header_text", with(0, original[0].payload.substr(0, 50)),
                   "(header): its JSON text is broken at byte"});
  cases.push_back({"scene_text", with(1, original[1].payload.substr(0, 100)),
                   "(scene): its JSON text is broken at byte"});
  cases.push_back({"scene_list", with(1, "[1, 2]"), "(scene): the top level is a list"});
  cases.push_back({"end_status", with(end, R"({"steps": 30, "status": 5})"),
                   "(end): status is 5, expected a string"});
  cases.push_back({"end_text", with(end, "{\"status\": \"ok"), "(end): its JSON text is broken"});
  for (const Case& c : cases) {
    const fs::path dir = WriteRun(c.name, c.bytes);
    const std::string error = ReadError(dir);
    EXPECT_NE(error.find(" is corrupt: chunk "), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
  // A format name of the wrong type: not a recording.
  json format = header;
  format["format"] = 5;
  const fs::path dir = WriteRun("format", with(0, format.dump()));
  EXPECT_NE(ReadError(dir).find("is not a swarmsim recording"), std::string::npos)
      << ReadError(dir);
  fs::remove_all(dir);
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
std::string OneObjectRecording(uint32_t poses, uint32_t colours, uint32_t readings, uint32_t cells,
                               uint32_t names, uint32_t samples) {
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

TEST(RecordingBoundsTest, StepRecordCountsAreCheckedBeforeAnythingIsAllocated) {
  // The well-formed one reads.
  const fs::path good = WriteRun("good", OneObjectRecording(1, 0, 0, 0, 0, 0));
  EXPECT_EQ(ReadError(good), "");
  fs::remove_all(good);
  // Counts of 4 billion in a 72-byte payload: an error naming the byte of
  // the payload, not an attempt to allocate 16 GB or more.
  constexpr uint32_t kHuge = 0xffffffff;
  struct Case {
    const char* name;
    std::string bytes;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"poses", OneObjectRecording(kHuge, 0, 0, 0, 0, 0),
       "does not decode at byte 20 of 72: a keyframe lists 4294967295 poses, but its scene has 1 "
       "objects"},
      {"colours", OneObjectRecording(1, kHuge, 0, 0, 0, 0),
       "does not decode at byte 48 of 72: it ends early"},
      {"readings", OneObjectRecording(1, 0, kHuge, 0, 0, 0),
       "does not decode at byte 52 of 72: it ends early"},
      {"cells", OneObjectRecording(1, 0, 0, kHuge, 0, 0),
       "does not decode at byte 56 of 72: paint cells, but the header has no paint layer"},
      {"names", OneObjectRecording(1, 0, 0, 0, kHuge, 0),
       "does not decode at byte 64 of 72: it ends early"},
      {"samples", OneObjectRecording(1, 0, 0, 0, 0, kHuge),
       "does not decode at byte 68 of 72: it ends early"},
  };
  for (const Case& c : cases) {
    const fs::path dir = WriteRun(c.name, c.bytes);
    const std::string error = ReadError(dir);
    EXPECT_NE(error.find(" is corrupt: chunk 3 at byte "), std::string::npos)
        << c.name << ": " << error;
    EXPECT_NE(error.find("(keyframe): its step record " + c.expected), std::string::npos)
        << c.name << ": " << error;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
}

// Sets a u32 field of the chunk header at `chunk_offset` (12: stored size, 16: raw size).
void SetHeaderField(std::string* bytes, uint64_t chunk_offset, int field_offset, uint32_t value) {
  std::memcpy(bytes->data() + chunk_offset + field_offset, &value, 4);
}

TEST(RecordingBoundsTest, ChunkSizesAreCheckedBeforeAnythingIsAllocated) {
  std::ifstream in(kDiffusion, std::ios::binary);
  const std::string original(std::istreambuf_iterator<char>(in), {});
  const RecordingInfo info = ScanRecording(kDiffusion);
  const uint32_t header_stored = info.chunks[0].stored_size;
  struct Case {
    const char* name;
    int field;  // 12: stored size, 16: raw size
    uint32_t value;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"raw_1gib", 16, 1u << 30,
       "(header): its header is damaged (" + std::to_string(header_stored) +
           " bytes stored for 1073741824 decompressed"},
      {"raw_200mib", 16, 200u << 20,
       "(header): its header says " + std::to_string(header_stored) +
           " stored bytes decompress to 209715200, more than zstd"},
      {"raw_frame", 16, 100 * header_stored,
       "(header): its payload's zstd frame decompresses to 480 bytes, but the chunk header says"},
  };
  for (const Case& c : cases) {
    std::string bytes = original;
    SetHeaderField(&bytes, 0, c.field, c.value);
    const fs::path dir = WriteRun(c.name, bytes);
    const std::string error = ReadError(dir);
    EXPECT_NE(error.find(" is corrupt: chunk 1 at byte 0 " + c.expected), std::string::npos)
        << c.name << ": " << error;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
  // A last chunk claiming more stored bytes than the file has: the file is
  // cut there (a run in progress), the chunks before it read.
  std::string bytes = original;
  const ChunkInfo& last = info.chunks.back();
  SetHeaderField(&bytes, last.offset, 12, 200u << 20);
  SetHeaderField(&bytes, last.offset, 16, 250u << 20);
  const fs::path dir = WriteRun("stored_beyond", bytes);
  const RecordingInfo cut = ScanRecording(dir);
  EXPECT_TRUE(cut.truncated);
  EXPECT_EQ(cut.step_records, info.step_records);
  EXPECT_EQ(ReadError(dir), "");
  fs::remove_all(dir);
}

TEST(RecordingBoundsTest, OnlyRegularFilesAreRead) {
  // A folder where the recording should be (a FIFO: RecordingBoundsCliTest).
  const fs::path dir = FreshTempDir("recording_bounds", "folder");
  fs::create_directories(dir / kRecordingFileName);
  EXPECT_NE(ReadError(dir).find(" is a folder, not a recording file"), std::string::npos)
      << ReadError(dir);
  fs::remove_all(dir);
}

// --- The program -------------------------------------------------------------------

// `swarmsim ARGS`, given at most a minute (a hang fails instead of blocking
// the suite); `limit_kb`: its address space, if not 0.
testing::CommandResult Swarmsim(const std::string& args, int limit_kb = 0) {
  std::string command = "timeout 60 " + std::string(SWARMSIM_BINARY) + " " + args;
  if (limit_kb > 0) command = "ulimit -v " + std::to_string(limit_kb) + "; " + command;
  return RunCommand(command);
}

TEST(RecordingBoundsCliTest, RecordInfoAndViewRefuseASceneThatPointsPastItsObjects) {
  for (const char* field : {"first", "count"}) {
    const fs::path dir = WriteRun(std::string("cli_") + field,
                                  WithScene([&](json& s) { s["robots"][0][field] = 1000000; }));
    const std::string where = (dir / kRecordingFileName).string() +
                              " is corrupt: chunk 2 at byte 332 (scene): robots[0]." + field +
                              " is 1000000";
    const auto info = Swarmsim("record-info " + dir.string());
    EXPECT_EQ(info.exit_code, 2) << info.output;
    EXPECT_NE(info.output.find("error: " + where), std::string::npos) << info.output;
    const auto exported =
        Swarmsim("view " + dir.string() + " --export " + (dir / "x.html").string());
    EXPECT_EQ(exported.exit_code, 2) << exported.output;
    EXPECT_NE(exported.output.find("error: " + where), std::string::npos) << exported.output;
    EXPECT_FALSE(fs::exists(dir / "x.html"));
    const auto served = Swarmsim("view " + dir.string() + " --port 0");
    EXPECT_EQ(served.exit_code, 2) << served.output;
    EXPECT_NE(served.output.find("error: " + where), std::string::npos) << served.output;
    fs::remove_all(dir);
  }
}

TEST(RecordingBoundsCliTest, AFifoInPlaceOfTheRecordingIsRefusedNotWaitedOn) {
  const fs::path dir = FreshTempDir("recording_bounds", "fifo");
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir / kRecordingFileName).c_str(), 0600), 0);
  const std::string message =
      (dir / kRecordingFileName).string() + " is a FIFO (named pipe), not a recording file";
  for (const std::string& args :
       {"record-info " + dir.string(), "record-info " + (dir / kRecordingFileName).string(),
        "view " + dir.string() + " --export " + (dir / "x.html").string(),
        "view " + dir.string() + " --port 0"}) {
    const auto r = Swarmsim(args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("error: " + message), std::string::npos) << args << ": " << r.output;
  }
  fs::remove_all(dir);
}

TEST(RecordingBoundsCliTest, AHugeChunkSizeIsRefusedWithinModestMemory) {
  // The header chunk's raw size says 1 GiB: refused as damaged by a program
  // given 700 MB of address space (it used to allocate it first).
  std::ifstream in(kDiffusion, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  SetHeaderField(&bytes, 0, 16, 1u << 30);
  const fs::path dir = WriteRun("cli_huge", bytes);
  const std::string where =
      (dir / kRecordingFileName).string() + " is corrupt: chunk 1 at byte 0 (header): ";
  for (const std::string& args :
       {"record-info " + dir.string(),
        "view " + dir.string() + " --export " + (dir / "x.html").string()}) {
    const auto r = Swarmsim(args, 700000);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("error: " + where + "its header is damaged"), std::string::npos)
        << args << ": " << r.output;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim::record
