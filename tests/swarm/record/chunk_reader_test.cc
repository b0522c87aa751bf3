// The bounded reading under the recording readers (swarm/record/chunk_reader.cc):
// chunk sizes checked before anything is allocated, only regular files read
// (never a FIFO waited on), by the library and the program.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "tests/swarm/record/damaged_recordings.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using namespace damaged;  // NOLINT: the damaged recordings' helpers
using testing::FreshTempDir;

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
