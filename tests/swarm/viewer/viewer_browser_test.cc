// The viewer page in headless Chromium, as a user sees it: served by
// `swarmsim view` and exported to one file opened from disk, it loads with
// no console error, draws the robots where the recording says, changes the
// picture when scrubbed, names a robot clicked, and follows a run that is
// still being recorded.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/swarm/run_program.h"
#include "tests/swarm/viewer/browser.h"

namespace swarmsim::testing {
namespace {
namespace fs = std::filesystem;

// Two boxes, pure red (mover#0) and pure blue (mover#1), slide along +x
// over a grey floor (tests/data/viewer/movers).
class ViewerBrowserTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!BrowserMissing().empty()) return;
    run_ = new fs::path(FreshTempDir("viewer_browser", "movers"));
    const CommandResult run =
        RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                   "/tests/data/viewer/movers/world.yaml --quiet --record --out " + run_->string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  static void TearDownTestSuite() {
    if (run_) fs::remove_all(*run_);
    delete run_;
    run_ = nullptr;
  }
  void SetUp() override {
    if (const std::string missing = BrowserMissing(); !missing.empty()) GTEST_SKIP() << missing;
  }

  // Checks the picture at the first and last step: each robot's colour at
  // the pixel its recorded position projects to, and not where it is not.
  static void ExpectRobotsDrawnWhereRecorded(Browser* browser) {
    browser->Run("swarmsimViewer.topDown();");
    const int last = browser->Run("return swarmsimViewer.recordCount - 1;").get<int>();
    ASSERT_GT(last, 5);
    json pixels[2][2];  // [record][robot] page pixel of the robot's centre
    Image images[2];
    const int records[2] = {0, last};
    for (int k = 0; k < 2; ++k) {
      browser->Run("swarmsimViewer.setRecord(" + std::to_string(records[k]) + ");");
      for (int robot = 0; robot < 2; ++robot)
        pixels[k][robot] =
            browser->Run("const p = swarmsimViewer.robotPosition(" + std::to_string(robot) +
                         "); return swarmsimViewer.project(p[0], p[1], p[2]);");
      images[k] = browser->Screenshot();
      ASSERT_GT(images[k].width, 0);
    }
    const auto colour_at = [](const Image& image, const json& pixel) {
      const int x = static_cast<int>(pixel["x"].get<double>());
      const int y = static_cast<int>(pixel["y"].get<double>());
      EXPECT_TRUE(x >= 0 && y >= 0 && x < image.width && y < image.height) << pixel.dump();
      return image.At(std::clamp(x, 0, image.width - 1), std::clamp(y, 0, image.height - 1));
    };
    const auto is_red = [](const uint8_t* c) { return c[0] > 150 && c[1] < 80 && c[2] < 80; };
    const auto is_blue = [](const uint8_t* c) { return c[2] > 150 && c[0] < 80 && c[1] < 80; };
    for (int k = 0; k < 2; ++k) {
      const uint8_t* red = colour_at(images[k], pixels[k][0]);
      const uint8_t* blue = colour_at(images[k], pixels[k][1]);
      EXPECT_TRUE(is_red(red)) << "record " << records[k] << ": " << int(red[0]) << ","
                               << int(red[1]) << "," << int(red[2]);
      EXPECT_TRUE(is_blue(blue)) << "record " << records[k] << ": " << int(blue[0]) << ","
                                 << int(blue[1]) << "," << int(blue[2]);
      // Scrubbing moved them: where each was at the other step, it is not now.
      EXPECT_FALSE(is_red(colour_at(images[k], pixels[1 - k][0]))) << "record " << records[k];
      EXPECT_FALSE(is_blue(colour_at(images[k], pixels[1 - k][1]))) << "record " << records[k];
    }
    // The red box moved 2 m along +x: far to the right on the screen.
    EXPECT_GT(pixels[1][0]["x"].get<double>() - pixels[0][0]["x"].get<double>(), 100);
  }

  static fs::path* run_;
};
fs::path* ViewerBrowserTest::run_ = nullptr;

TEST_F(ViewerBrowserTest, ServedPageDrawsTheRobotsWhereTheRecordingSays) {
  ViewServer server(run_->string(), (*run_ / "server.log").string());
  ASSERT_FALSE(server.Address().empty()) << server.Output();
  EXPECT_NE(server.Address().find("http://127.0.0.1:"), std::string::npos);
  Browser browser;
  browser.Open(server.Address());
  ASSERT_EQ(browser.WaitForViewer(), "");
  ExpectRobotsDrawnWhereRecorded(&browser);
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
}

// What the view draws, counted: objects drawn as solids, as lights, and rays.
json DrawnCounts(Browser* browser) {
  return browser->Run(
      "const v = swarmsimViewer.view, count = (led) => v.groups.filter((g) => g.userData.led === "
      "led).reduce((n, g) => n + g.userData.ids.length, 0);"
      "return {solids: count(false), lights: count(true), rays: v.sensorIds.length};");
}

// A recording of format 1.1 lists its objects as their types declare their
// visuals; one of format 1.0 (tests/data/recordings) by their types: both
// are drawn.
TEST_F(ViewerBrowserTest, DrawsTheObjectsOfFormat1_1And1_0Recordings) {
  {
    ViewServer server(run_->string(), (*run_ / "server_visuals.log").string());
    Browser browser;
    browser.Open(server.Address());
    ASSERT_EQ(browser.WaitForViewer(), "");
    // The two movers' bodies and the arena's four walls.
    EXPECT_EQ(DrawnCounts(&browser), json::parse(R"({"solids": 6, "lights": 0, "rays": 0})"));
    EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  }
  const fs::path data = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/recordings";
  {
    // 9 robots with an LED each.
    ViewServer server((data / "leds").string(), (*run_ / "server_leds.log").string());
    Browser browser;
    browser.Open(server.Address());
    ASSERT_EQ(browser.WaitForViewer(), "");
    const json counts = DrawnCounts(&browser);
    EXPECT_EQ(counts["lights"], 9) << counts;
    EXPECT_GE(counts["solids"], 9) << counts;
    EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  }
  {
    // 10 robots with 24 proximity rays each, drawn red or blue by their readings.
    ViewServer server((data / "diffusion").string(), (*run_ / "server_rays.log").string());
    Browser browser;
    browser.Open(server.Address());
    ASSERT_EQ(browser.WaitForViewer(), "");
    EXPECT_EQ(DrawnCounts(&browser)["rays"], 240);
    browser.Run("swarmsimViewer.view.setShow('rays', true);");
    EXPECT_EQ(browser.Run("const c = swarmsimViewer.view.rays.geometry.attributes.color.array;"
                          "return [...c].every((v) => [1, 0.2, 0.3, 0.8].some((w) => "
                          "Math.abs(v - w) < 1e-6));"),
              true);
    EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  }
}

TEST_F(ViewerBrowserTest, ClickingARobotShowsItsName) {
  ViewServer server(run_->string(), (*run_ / "server.log").string());
  Browser browser;
  browser.Open(server.Address());
  ASSERT_EQ(browser.WaitForViewer(), "");
  browser.Run("swarmsimViewer.topDown(); swarmsimViewer.setRecord(10);");
  for (int robot : {1, 0}) {
    const json pixel =
        browser.Run("const p = swarmsimViewer.robotPosition(" + std::to_string(robot) +
                    "); return swarmsimViewer.project(p[0], p[1], p[2]);");
    browser.Click(static_cast<int>(pixel["x"].get<double>()),
                  static_cast<int>(pixel["y"].get<double>()));
    EXPECT_EQ(browser.Run("return swarmsimViewer.selectedName();"),
              "mover#" + std::to_string(robot));
  }
  // Its model and parameters are listed with it (mover#0's speed: 1).
  const std::string info = browser.Run("return document.getElementById('info').textContent;");
  EXPECT_NE(info.find("model mover"), std::string::npos) << info;
  EXPECT_NE(info.find("speed1"), std::string::npos) << info;
  // The world's metric and the one the movers' script records (x) are there
  // to plot.
  EXPECT_EQ(browser.Run("return swarmsimViewer.metricNames();"),
            json::array({"mean_nearest_neighbor_distance", "x"}));
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
}

TEST_F(ViewerBrowserTest, ExportedFilePlaysFromDisk) {
  const fs::path html = *run_ / "run.html";
  const CommandResult exported =
      RunProgram("view " + run_->string() + " --export " + html.string());
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  // Nothing to fetch: no server runs, the page opens from disk.
  Browser browser;
  browser.Open("file://" + html.string());
  ASSERT_EQ(browser.WaitForViewer(), "");
  ExpectRobotsDrawnWhereRecorded(&browser);
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
}

TEST_F(ViewerBrowserTest, FollowsARecordingThatIsStillBeingWritten) {
  // A run in progress: the first half of the file (cut inside a chunk),
  // then the rest appended while the page is open.
  const std::string bytes = ReadFile(*run_ / "recording.swrec");
  const fs::path live = FreshTempDir("viewer_browser", "live");
  fs::create_directories(live);
  std::ofstream(live / "recording.swrec", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  ViewServer server(live.string(), (live / "server.log").string());
  Browser browser;
  browser.Open(server.Address());
  ASSERT_EQ(browser.WaitForViewer(), "");
  const int first = browser.Run("return swarmsimViewer.recordCount;").get<int>();
  EXPECT_TRUE(browser.Run("return swarmsimViewer.live;").get<bool>());
  std::ofstream(live / "recording.swrec", std::ios::binary | std::ios::app)
      << bytes.substr(bytes.size() / 2);
  EXPECT_TRUE(
      WaitUntil([&] { return browser.Run("return swarmsimViewer.ended;").get<bool>(); }, 10));
  const int all = browser.Run("return swarmsimViewer.recordCount;").get<int>();
  EXPECT_GT(all, first);
  // It stays on the newest step as the run goes.
  EXPECT_EQ(browser.Run("return swarmsimViewer.record;").get<int>(), all - 1);
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  fs::remove_all(live);
}

// Whether `run --view`, logging to `log`, says it serves after its run (or
// has ended) within 30 s.
bool ServingOrEnded(ChildProcess* run, const std::string& log) {
  return WaitUntil(
      [&] { return FileText(log).find("still serving") != std::string::npos || !run->Running(); },
      30);
}

TEST_F(ViewerBrowserTest, RunWithViewServesThePageWhileAndAfterTheRun) {
  const fs::path out = FreshTempDir("viewer_browser", "run_view");
  const std::string log = fs::path(FreshTempDir("viewer_browser", "run_view_log")).string();
  ChildProcess run({SWARMSIM_BINARY, "run",
                    std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/viewer/movers/world.yaml",
                    "--quiet", "--out", out.string(), "--view", "--view-port", "0"},
                   log);
  std::string address;
  ASSERT_TRUE(ServingOrEnded(&run, log)) << FileText(log);
  const std::string text = FileText(log);
  const size_t at = text.find("http://127.0.0.1:");
  ASSERT_NE(at, std::string::npos) << text;
  address = text.substr(at, text.find(' ', at) - at);
  Browser browser;
  browser.Open(address);
  ASSERT_EQ(browser.WaitForViewer(), "");
  EXPECT_TRUE(browser.Run("return swarmsimViewer.ended;").get<bool>());
  EXPECT_EQ(browser.Run("return swarmsimViewer.robotCount;").get<int>(), 2);
  // It served until stopped, and exits as its summary says: the run was ok.
  EXPECT_EQ(run.Stop(), 0);
  fs::remove_all(out);
  fs::remove(log);
}

// A run that fails with --view says why before it serves (its error was
// never printed: the page stayed, and the exit status after Ctrl-C was 1).
// No browser needed.
TEST(ViewCliTest, AFailedRunSaysWhyBeforeItServes) {
  const fs::path out = FreshTempDir("viewer_browser", "run_view_error");
  const std::string log = fs::path(FreshTempDir("viewer_browser", "run_view_error_log")).string();
  ChildProcess run(
      {SWARMSIM_BINARY, "run", std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/cli/broken.yaml",
       "--quiet", "--out", out.string(), "--view", "--view-port", "0"},
      log);
  ASSERT_TRUE(ServingOrEnded(&run, log)) << FileText(log);
  const std::string text = FileText(log);
  EXPECT_NE(text.find("still serving"), std::string::npos) << text;
  EXPECT_NE(text.find("error: "), std::string::npos) << text;
  EXPECT_EQ(run.Stop(), 1) << "as its summary says";
  fs::remove_all(out);
  fs::remove(log);
}

}  // namespace
}  // namespace swarmsim::testing
