// swarmsim view DIR (swarm/cli/view_command.cc): --export writes one page
// holding the recording's whole chunks, and what cannot be shown is
// refused before anything is served or written.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunProgram;

const fs::path kRecordings = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/recordings";

fs::path TempDir(const std::string& name) {
  const fs::path dir = swarmsim::testing::FreshTempDir("swarmsim_view_cli", name);
  fs::create_directories(dir);
  return dir;
}

// The base64 text of the recording inside an exported page.
std::string EncodedRecording(const std::string& page) {
  const std::string open = "<script id=\"swarmsim-recording\" type=\"application/octet-stream\">";
  const size_t begin = page.find(open);
  if (begin == std::string::npos) return "(none)";
  const size_t from = begin + open.size();
  return page.substr(from, page.find("</script>", from) - from);
}

size_t Base64Length(uint64_t bytes) { return 4 * ((bytes + 2) / 3); }

TEST(ViewCommandTest, ExportWritesOnePageWithTheWholeRecording) {
  const fs::path dir = TempDir("export");
  const fs::path html = dir / "run.html";
  const Result r =
      RunProgram("view " + (kRecordings / "diffusion").string() + " --export " + html.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("swarmsim view: wrote " + html.string() + " (" +
                          std::to_string(fs::file_size(html)) + " bytes)"),
            std::string::npos)
      << r.output;
  const std::string recording = ReadFile(kRecordings / "diffusion/recording.swrec");
  const std::string encoded = EncodedRecording(ReadFile(html));
  EXPECT_EQ(encoded.size(), Base64Length(recording.size()));
  EXPECT_EQ(encoded.substr(0, 4), "U1dS") << "base64 of the magic, SWR";
  fs::remove_all(dir);
}

TEST(ViewCommandTest, ExportOfACutRecordingHoldsItsWholeChunksOnly) {
  const fs::path dir = TempDir("export_cut");
  const fs::path html = dir / "cut.html";
  const Result r =
      RunProgram("view " + (kRecordings / "truncated").string() + " --export " + html.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // What it says of the file names where the last whole chunk ends.
  const std::string said = "ends inside a chunk at byte ";
  const size_t at = r.output.find(said);
  ASSERT_NE(at, std::string::npos) << r.output;
  ASSERT_TRUE(std::isdigit(static_cast<unsigned char>(r.output[at + said.size()]))) << r.output;
  const uint64_t valid = std::stoull(r.output.substr(at + said.size()));
  EXPECT_LT(valid, fs::file_size(kRecordings / "truncated/recording.swrec"));
  EXPECT_EQ(EncodedRecording(ReadFile(html)).size(), Base64Length(valid));
  fs::remove_all(dir);
}

TEST(ViewCommandTest, WhatCannotBeShownIsRefusedFirst) {
  const fs::path dir = TempDir("refused");
  Result r =
      RunProgram("view " + (dir / "nowhere").string() + " --export " + (dir / "x.html").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: '" + (dir / "nowhere").string() +
                          "' is not a folder: give the output folder of a run (swarmsim run "
                          "WORLD --out DIR --record)"),
            std::string::npos)
      << r.output;
  // Every step record is decoded before a page is written.
  r = RunProgram("view " + (kRecordings / "corrupt").string() + " --export " +
                 (dir / "x.html").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is corrupt: chunk 11 at byte"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "x.html"));
  // A page that cannot be written: the run's folder was fine, the output not.
  r = RunProgram("view " + (kRecordings / "diffusion").string() + " --export " +
                 (dir / "no/such/folder/x.html").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("error: "), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The page is renamed over its name: it replaced the recording it was made
// from (record-info then said "not a swarmsim recording"), or a pipe.
TEST(ViewCommandTest, ThePageGoesOverNoneOfTheRunsFilesNorAPipe) {
  const fs::path dir = TempDir("own_files");
  fs::copy(kRecordings / "diffusion", dir / "run", fs::copy_options::recursive);
  const std::string recording = ReadFile(dir / "run" / "recording.swrec");
  Result r = RunProgram("view " + (dir / "run").string() + " --export " +
                        (dir / "run" / "recording.swrec").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is the run's own recording.swrec in '"), std::string::npos) << r.output;
  EXPECT_EQ(ReadFile(dir / "run" / "recording.swrec"), recording);
  // Through a symbolic link to it, the same.
  fs::create_symlink(dir / "run" / "recording.swrec", dir / "link.html");
  r = RunProgram("view " + (dir / "run").string() + " --export " + (dir / "link.html").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(ReadFile(dir / "run" / "recording.swrec"), recording);
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  r = RunProgram("view " + (dir / "run").string() + " --export " + (dir / "pipe").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("it is a FIFO (named pipe), not an ordinary file"), std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::is_fifo(dir / "pipe"));
  // Into the run's folder under another name: written.
  r = RunProgram("view " + (dir / "run").string() + " --export " +
                 (dir / "run" / "page.html").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  fs::remove_all(dir);
}

TEST(ViewCommandTest, OptionsSayWhatTheyExpect) {
  const std::string run = (kRecordings / "diffusion").string();
  Result r = RunProgram("view " + run + " --port 70000");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--port: expected a whole number from 0 to 65535, got '70000'"),
            std::string::npos)
      << r.output;
  r = RunProgram("view " + run + " --export ''");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--export: expected a file"), std::string::npos) << r.output;
  r = RunProgram("view ''");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("expected a folder"), std::string::npos) << r.output;
}

TEST(ViewCommandTest, AMissingHttpModuleIsAnErrorNamingWhereItWasLookedFor) {
  // The server is a module opened when it is made (swarm/viewer/http_module.h);
  // --export needs none.
  const fs::path dir = TempDir("missing_http");
  const std::string nowhere = (dir / "nowhere" / "libswarmsim_http.so").string();
  const std::string run = (kRecordings / "diffusion").string();
  Result r = swarmsim::testing::RunCommand("SWARMSIM_HTTP_MODULE=" + nowhere + " " +
                                           SWARMSIM_BINARY + " view " + run + " --port 0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: the viewer's server needs swarmsim's HTTP module"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(nowhere + ": cannot open shared object file"), std::string::npos)
      << r.output;
  r = swarmsim::testing::RunCommand("SWARMSIM_HTTP_MODULE=" + nowhere + " " + SWARMSIM_BINARY +
                                    " view " + run + " --export " + (dir / "x.html").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

}  // namespace
