// The viewer page embedded into the program (swarm/viewer/assets.cc): the
// bytes of web/index.html and of the bundled script, whole, nothing more.
#include "swarm/viewer/assets.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim::viewer {
namespace {

namespace fs = std::filesystem;

TEST(AssetsTest, ThePageIsIndexHtmlByteForByte) {
  const std::string html =
      testing::ReadFile(fs::path(SWARMSIM_SOURCE_DIR) / "swarm/viewer/web/index.html");
  ASSERT_FALSE(html.empty());
  EXPECT_EQ(PageHtml(), html);
  // Where the scripts go, once.
  const std::string_view page = PageHtml();
  const size_t mark = page.find("<!--SWARMSIM_SCRIPTS-->");
  ASSERT_NE(mark, std::string_view::npos);
  EXPECT_EQ(page.find("<!--SWARMSIM_SCRIPTS-->", mark + 1), std::string_view::npos);
}

TEST(AssetsTest, TheScriptIsTheWholeBundle) {
  // The bundle esbuild wrote into the build tree (tests run from build/tests/).
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  const std::string bundle =
      testing::ReadFile(exe.parent_path().parent_path() / "swarm/viewer/viewer.bundle.js");
  ASSERT_FALSE(bundle.empty()) << "no viewer.bundle.js beside " << exe;
  EXPECT_EQ(PageScript().size(), bundle.size());
  EXPECT_TRUE(PageScript() == bundle);
  EXPECT_EQ(PageScript().find('\0'), std::string_view::npos);
}

}  // namespace
}  // namespace swarmsim::viewer
