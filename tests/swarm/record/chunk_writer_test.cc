// The recorder's back end (swarm/record/chunk_writer.cc): chunks appended in
// order from a thread of its own, step records encoded against the one
// before, and everything read back as it was captured; a file that cannot be
// created or written is an error naming it.
#include "swarm/record/chunk_writer.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "tests/swarm/run_program.h"

#if !defined(__SANITIZE_ADDRESS__)
// Allocations of this many bytes or more fail while it is not 0: a writer
// thread that runs out of memory (AddressSanitizer's own operator new is
// not replaced).
std::atomic<size_t> g_refuse_from{0};

void* operator new(size_t n) {
  const size_t refuse = g_refuse_from.load();
  if (refuse != 0 && n >= refuse) throw std::bad_alloc();
  if (void* p = std::malloc(n != 0 ? n : 1)) return p;
  throw std::bad_alloc();
}
// (GCC takes the replaced pair for a mismatch once it inlines them.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
#endif

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::ReadFile;

constexpr const char* kHeader =
    R"({"format": "swarmsim-recording", "version": [1, 0], "metrics": []})";
// One robot of one object.
constexpr const char* kScene = R"({"object_count": 1, "templates": [{"objects": [{"parent": -1}]}],
    "robots": [{"index": 0, "first": 0, "count": 1, "template": 0}], "objects": [], "meshes": []})";

// A step record of the one object at (x, y) in 0.1 mm with colour `rgba`,
// and the samples given; a delta after the keyframe that named one metric.
std::unique_ptr<StepSnapshot> Step(ChunkWriter* writer, uint32_t record, bool keyframe, int32_t x,
                                   int32_t y, uint32_t rgba, std::vector<SampleRow> samples = {}) {
  std::unique_ptr<StepSnapshot> s = writer->TakeSnapshot();
  s->step = record;
  s->time = 0.1 * record;
  s->record = record;
  s->keyframe = keyframe;
  s->pose = {{x, y, 0, 32767, 0, 0, 0}};
  s->color = {rgba};
  s->reading = {kNoDetection};
  s->first_name = keyframe ? 0 : 1;  // metric names from this id on
  s->names.clear();
  s->samples = std::move(samples);
  return s;
}

TEST(ChunkWriterTest, StepRecordsReadBackAsCaptured) {
  const fs::path dir = FreshTempDir("chunk_writer", "steps");
  fs::create_directories(dir);
  const fs::path file = dir / kRecordingFileName;
  uint64_t written = 0;
  {
    ChunkWriter writer(file, 3);
    writer.AddJson(static_cast<uint8_t>(ChunkKind::kHeader), 0, kHeader);
    writer.AddScene(0, kScene, SceneLists{1, {0}, {}});
    auto first = Step(&writer, 0, true, 10000, -5000, 0x010000ffu, {{0, 0, 0, 0.25}});
    first->names = {"speed"};
    writer.AddStep(std::move(first));
    writer.AddStep(Step(&writer, 1, false, 12000, -5000, 0x010000ffu, {{0, -1, 1, 3.5}}));
    writer.AddStep(Step(&writer, 2, false, 12000, -5000, 0x0100ff00u));
    writer.Flush();
    written = writer.bytes_written();
  }  // (the destructor writes whatever is still queued)
  EXPECT_EQ(written, fs::file_size(file));
  RecordingPlayer player(dir);
  EXPECT_EQ(player.info().step_records, 3);
  EXPECT_FALSE(player.info().truncated);
  ASSERT_EQ(player.info().chunks.size(), 5u);
  EXPECT_EQ(player.info().chunks[2].kind, static_cast<uint8_t>(ChunkKind::kKeyframe));
  EXPECT_EQ(player.info().chunks[3].kind, static_cast<uint8_t>(ChunkKind::kDelta));
  ASSERT_TRUE(player.Next());
  EXPECT_EQ(player.step(), 0);
  EXPECT_NEAR(player.world_pose(0).p.x, 10000 * kPositionUnit, 1e-12);
  EXPECT_NEAR(player.world_pose(0).p.y, -5000 * kPositionUnit, 1e-12);
  EXPECT_EQ(player.color_rgba(0), 0x010000ffu);
  ASSERT_EQ(player.samples().size(), 1u);
  EXPECT_EQ(player.samples()[0].name, "speed");
  EXPECT_EQ(player.samples()[0].robot, 0);
  EXPECT_EQ(player.samples()[0].value, 0.25);
  ASSERT_TRUE(player.Next());
  EXPECT_EQ(player.step(), 1);
  EXPECT_NEAR(player.time(), 0.1, 1e-12);
  EXPECT_NEAR(player.world_pose(0).p.x, 12000 * kPositionUnit, 1e-12);
  EXPECT_EQ(player.color_rgba(0), 0x010000ffu);
  ASSERT_EQ(player.samples().size(), 1u);
  EXPECT_EQ(player.samples()[0].name, "speed") << "a name once given is kept";
  EXPECT_EQ(player.samples()[0].robot, -1);
  EXPECT_EQ(player.samples()[0].value, 3.5);
  ASSERT_TRUE(player.Next());
  EXPECT_NEAR(player.world_pose(0).p.x, 12000 * kPositionUnit, 1e-12);
  EXPECT_EQ(player.color_rgba(0), 0x0100ff00u);
  EXPECT_TRUE(player.samples().empty());
  EXPECT_FALSE(player.Next());
  // A delta holds only what changed: the unchanged pose costs nothing.
  EXPECT_LT(player.info().chunks[4].raw_size, player.info().chunks[3].raw_size);
  fs::remove_all(dir);
}

TEST(ChunkWriterTest, AChunksBytesHoldItsPayload) {
  const fs::path dir = FreshTempDir("chunk_writer", "bytes");
  fs::create_directories(dir);
  const std::string header = EncodeChunkBytes(1, 0, kHeader);
  ASSERT_GE(header.size(), kChunkHeaderSize);
  EXPECT_EQ(header.substr(0, 4), "SWRC");
  const std::string scene = EncodeChunkBytes(2, 7, kScene);
  std::ofstream(dir / kRecordingFileName, std::ios::binary) << header << scene;
  const RecordingInfo info = ScanRecording(dir);
  ASSERT_EQ(info.chunks.size(), 2u);
  EXPECT_EQ(info.chunks[1].offset, header.size());
  EXPECT_EQ(info.chunks[1].step, 7u);
  EXPECT_EQ(info.chunks[1].raw_size, std::string(kScene).size());
  EXPECT_EQ(info.chunks[1].stored_size + kChunkHeaderSize, scene.size());
  EXPECT_EQ(ReadChunk(dir / kRecordingFileName, info.chunks[0]), kHeader);
  EXPECT_EQ(ReadChunk(dir / kRecordingFileName, info.chunks[1]), kScene);
  EXPECT_EQ(info.header_json, kHeader);
  fs::remove_all(dir);
}

TEST(ChunkWriterTest, AFileThatCannotBeCreatedOrWrittenIsNamed) {
  const fs::path missing = FreshTempDir("chunk_writer", "missing") / "recording.swrec";
  try {
    ChunkWriter writer(missing, 3);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot create " + missing.string() + ": No such file or directory");
  }
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full: a full disk not tried";
  // A full disk: the error comes back to the simulation's thread.
  ChunkWriter writer("/dev/full", 3);
  writer.AddJson(static_cast<uint8_t>(ChunkKind::kHeader), 0, kHeader);
  try {
    writer.Flush();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write /dev/full: No space left on device");
  }
  EXPECT_THROW(writer.AddJson(static_cast<uint8_t>(ChunkKind::kEnd), 0, "{}"), Error)
      << "after a failure, every call says so";
}

// The writer's thread out of memory while it compresses a chunk: the run
// hears it, the chunk is cut off, and the end chunk still follows (the
// file lost its end, and record-info said the run was killed).
TEST(ChunkWriterTest, RunningOutOfMemoryLeavesAWholeFileWithItsEnd) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "operator new is AddressSanitizer's";
#else
  const fs::path dir = FreshTempDir("chunk_writer", "oom");
  fs::create_directories(dir);
  {
    ChunkWriter writer(dir / kRecordingFileName, 3);
    writer.AddJson(static_cast<uint8_t>(ChunkKind::kHeader), 0, kHeader);
    writer.Flush();
    std::string large(8 << 20, 'x');  // its compression buffer: 8 MiB
    g_refuse_from = 4 << 20;
    writer.AddJson(static_cast<uint8_t>(ChunkKind::kScene), 1, std::move(large));
    try {
      writer.Flush();
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "out of memory while writing the recording: its later steps are left out");
    }
    g_refuse_from = 0;
    writer.AddJson(static_cast<uint8_t>(ChunkKind::kEnd), 1,
                   R"({"status": "error", "error": "out of memory"})");
  }
  const RecordingInfo info = ScanRecording(dir);
  ASSERT_EQ(info.chunks.size(), 2u);
  EXPECT_TRUE(info.ended);
  EXPECT_EQ(info.end_status, "error");
  fs::remove_all(dir);
#endif
}

}  // namespace
}  // namespace swarmsim::record
