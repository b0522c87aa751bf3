// Reading a recording (swarm/record/reader.cc): a folder without one says how
// to make one, a cut file reads its whole step records, a corrupt chunk or a
// newer format is named, and step records whose counts pass their payload
// are refused before anything is allocated.
#include "swarm/record/reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/record/format.h"
#include "swarm/record/writer.h"
#include "tests/swarm/record/damaged_recordings.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using damaged::ExpectUsersMessage;
using damaged::OneObjectRecording;
using damaged::ReadError;
using damaged::WriteRun;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("recording_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string Data(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/recordings/" + name;
}

std::string ErrorOf(const fs::path& path) {
  try {
    ScanRecording(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(RecordingReaderTest, AFolderWithoutARecordingSaysHowToMakeOne) {
  const fs::path dir = TempDir("empty");
  EXPECT_EQ(ErrorOf(dir), dir.string() +
                              " has no recording.swrec: record a run with swarmsim run WORLD "
                              "--out " +
                              dir.string() + " --record");
  fs::remove_all(dir);
}

TEST(RecordingReaderTest, ATruncatedFileReadsItsWholeStepsAndSaysSo) {
  const RecordingInfo info = ScanRecording(Data("truncated"));
  EXPECT_TRUE(info.truncated);
  EXPECT_FALSE(info.ended);
  EXPECT_EQ(info.step_records, 30);
  EXPECT_NE(info.Describe().find("ends inside a chunk at byte " + std::to_string(info.valid_size)),
            std::string::npos)
      << info.Describe();
  RecordingPlayer player(Data("truncated"));
  int n = 0;
  while (player.Next()) ++n;
  EXPECT_EQ(n, 30);
  EXPECT_EQ(player.step(), 29);
  // Cut anywhere: never an error, always the whole records before the cut.
  const std::string bytes = [] {
    std::ifstream in(Data("diffusion") + "/recording.swrec", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  const fs::path dir = TempDir("cut");
  int64_t last = -1;
  // Inside the header chunk: not yet a recording (a run that just started).
  const size_t header_end = ScanRecording(Data("diffusion")).chunks[1].offset;
  std::ofstream(dir / "recording.swrec", std::ios::binary) << bytes.substr(0, header_end - 1);
  EXPECT_NE(ErrorOf(dir).find("holds no whole chunk yet"), std::string::npos) << ErrorOf(dir);
  for (size_t size = header_end; size < bytes.size(); size += 97) {
    std::ofstream(dir / "recording.swrec", std::ios::binary) << bytes.substr(0, size);
    const RecordingInfo cut = ScanRecording(dir);
    EXPECT_GE(cut.step_records, last);
    last = cut.step_records;
    EXPECT_LE(cut.valid_size, size);
  }
  EXPECT_GE(last, 30);
  std::ofstream(dir / "recording.swrec", std::ios::binary) << bytes;
  EXPECT_EQ(ScanRecording(dir).step_records, 31);
  fs::remove_all(dir);
}

TEST(RecordingReaderTest, ACorruptChunkIsNamedWithItsOffset) {
  const std::string error = ErrorOf(Data("corrupt"));
  EXPECT_NE(error.find("is corrupt: chunk 11 at byte "), std::string::npos) << error;
  EXPECT_NE(error.find("checksum mismatch"), std::string::npos) << error;
  // Not a recording at all.
  const fs::path dir = TempDir("notone");
  std::ofstream(dir / "recording.swrec") << "hello, this is text and no recording at all\n";
  EXPECT_NE(ErrorOf(dir).find("is not a swarmsim recording"), std::string::npos) << ErrorOf(dir);
  fs::remove_all(dir);
}

TEST(RecordingReaderTest, ANewerMajorVersionIsRefusedNamingBoth) {
  EXPECT_NE(ErrorOf(Data("newer_version"))
                .find("is a recording of format version 2.0, newer than this swarmsim reads (1.2)"),
            std::string::npos)
      << ErrorOf(Data("newer_version"));
  // A newer minor version reads.
  const fs::path dir = TempDir("minor");
  std::ofstream(dir / "recording.swrec", std::ios::binary)
      << EncodeChunk(1, 0, R"({"format": "swarmsim-recording", "version": [1, 7], "metrics": []})");
  const RecordingInfo info = ScanRecording(dir);
  EXPECT_EQ(info.version_minor, 7);
  EXPECT_EQ(info.step_records, 0);
  // Its size in bytes, not "0.00 MB".
  EXPECT_NE(info.Describe().find("0 step records, " + std::to_string(info.valid_size) + " bytes"),
            std::string::npos)
      << info.Describe();
  fs::remove_all(dir);
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

}  // namespace
}  // namespace swarmsim::record
