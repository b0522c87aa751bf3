// The viewer page as served and as exported (swarm/viewer/page.cc): the
// served page loads viewer.js; an exported page holds the script inline and
// the recording base64-encoded, and plays from disk.
#include "swarm/viewer/page.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "framework/error.h"
#include "swarm/viewer/assets.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::viewer {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMark = "<!--SWARMSIM_SCRIPTS-->";
const fs::path kDiffusion = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/recordings/diffusion";

// index.html with its scripts mark replaced by `scripts`.
std::string PageWith(const std::string& scripts) {
  std::string html(PageHtml());
  html.replace(html.find(kMark), kMark.size(), scripts);
  return html;
}

// The recording inside an exported page (the text of its recording script).
std::string EncodedRecording(const std::string& page) {
  const std::string open = "<script id=\"swarmsim-recording\" type=\"application/octet-stream\">";
  const size_t begin = page.find(open);
  if (begin == std::string::npos) return "(none)";
  const size_t from = begin + open.size();
  return page.substr(from, page.find("</script>", from) - from);
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(PageTest, TheServedPageLoadsViewerJs) {
  EXPECT_EQ(ServedPage(), PageWith("<script src=\"viewer.js\"></script>"));
  EXPECT_EQ(ServedPage().find(kMark), std::string::npos);
}

TEST(PageTest, AnExportedPageHoldsTheRecordingInBase64) {
  // RFC 4648's alphabet and padding, every length modulo 3.
  EXPECT_EQ(EncodedRecording(ExportedPage("")), "");
  EXPECT_EQ(EncodedRecording(ExportedPage("M")), "TQ==");
  EXPECT_EQ(EncodedRecording(ExportedPage("Ma")), "TWE=");
  EXPECT_EQ(EncodedRecording(ExportedPage("Man")), "TWFu");
  EXPECT_EQ(EncodedRecording(ExportedPage(std::string("\xff\xfe\x00", 3))), "//4A");
  EXPECT_EQ(EncodedRecording(ExportedPage("SWRC\x01")), "U1dSQwE=");
}

TEST(PageTest, TheInlineScriptCannotEndItsScriptElementEarly) {
  const std::string page = ExportedPage("x");
  EXPECT_EQ(page.find(kMark), std::string::npos);
  EXPECT_EQ(page.find("<script src="), std::string::npos) << "nothing to load from beside it";
  // Only the two script elements close: the recording's and the script's,
  // whatever "</script" the bundled script holds in its strings.
  EXPECT_EQ(Count(page, "</script>"), Count(std::string(PageHtml()), "</script>") + 2);
  EXPECT_EQ(Count(page, "</script") + Count(page, "</SCRIPT"),
            Count(std::string(PageHtml()), "</script") + 2);
  // The rest of the script is there whole.
  EXPECT_GT(page.size(), PageScript().size());
}

TEST(PageTest, ExportFolderWritesTheFirstBytesOfTheRecording) {
  const fs::path dir = testing::FreshTempDir("viewer_page", "export");
  fs::create_directories(dir);
  const std::string bytes = testing::ReadFile(kDiffusion / "recording.swrec");
  ASSERT_GT(bytes.size(), 6u);
  ExportFolder(kDiffusion, 6, dir / "six.html");
  EXPECT_EQ(testing::ReadFile(dir / "six.html"), ExportedPage(bytes.substr(0, 6)));
  ExportFolder(kDiffusion, bytes.size(), dir / "all.html");
  EXPECT_EQ(testing::ReadFile(dir / "all.html"), ExportedPage(bytes));
  fs::remove_all(dir);
}

TEST(PageTest, ExportFolderWritesNothingWhenTheRecordingCannotBeRead) {
  const fs::path dir = testing::FreshTempDir("viewer_page", "unreadable");
  fs::create_directories(dir);
  const uint64_t size = fs::file_size(kDiffusion / "recording.swrec");
  for (const auto& [folder, want] :
       {std::pair{kDiffusion, size + 1}, std::pair{dir / "nothing", uint64_t{10}}}) {
    try {
      ExportFolder(folder, want, dir / "x.html");
      ADD_FAILURE() << folder << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "cannot read '" + (folder / "recording.swrec").string() + "'");
    }
    EXPECT_FALSE(fs::exists(dir / "x.html")) << folder;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim::viewer
