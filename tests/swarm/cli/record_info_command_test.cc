// swarmsim record-info DIR (swarm/cli/record_info_command.cc): what a run's
// recording holds, and what is wrong with a damaged one, with exit code 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::RunProgram;

TEST(RecordCliTest, RecordInfoNamesWhatIsWrong) {
  const fs::path empty = FreshTempDir("record_cli", "empty");
  fs::create_directories(empty);
  const auto none = RunProgram("record-info " + empty.string());
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.output.find("has no recording.swrec: record a run with swarmsim run WORLD --out"),
            std::string::npos)
      << none.output;
  const std::string data = std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/recordings/";
  const auto corrupt = RunProgram("record-info " + data + "corrupt");
  EXPECT_EQ(corrupt.exit_code, 2);
  EXPECT_NE(corrupt.output.find("is corrupt: chunk 11 at byte"), std::string::npos)
      << corrupt.output;
  const auto newer = RunProgram("record-info " + data + "newer_version");
  EXPECT_EQ(newer.exit_code, 2);
  EXPECT_NE(newer.output.find("format version 2.0, newer than this swarmsim reads (1.2)"),
            std::string::npos)
      << newer.output;
  const auto truncated = RunProgram("record-info " + data + "truncated");
  EXPECT_EQ(truncated.exit_code, 0);
  EXPECT_NE(truncated.output.find("read the 30 whole step records before it"), std::string::npos)
      << truncated.output;
  fs::remove_all(empty);
}

TEST(RecordCliTest, RecordInfoSummarisesAGoodRecordingFromItsFolderOrFile) {
  const std::string dir = std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/recordings/diffusion";
  for (const std::string& path : {dir, dir + "/recording.swrec"}) {
    const auto info = RunProgram("record-info " + path);
    EXPECT_EQ(info.exit_code, 0) << info.output;
    // Every step record decoded; the scene's objects counted.
    EXPECT_NE(info.output.find("decoded         31 step records\n"), std::string::npos)
        << info.output;
    EXPECT_NE(info.output.find("objects         274 in the last scene\n"), std::string::npos)
        << info.output;
  }
  const auto missing = RunProgram("record-info " + dir + "/nowhere");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("error: "), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace swarmsim::record
