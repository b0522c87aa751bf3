// Snapshots and video of a run (swarmsim run --snapshot-every, --video,
// --camera; modules/rendering/video), as a user runs them: the program on
// small worlds, the PNGs read back and the videos decoded back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "framework/sanitizers.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/video/video_writer.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using testing::FreshTempDir;
using testing::RunProgram;

// Where a colour is in an image (columns [x0, x1)): the centre of its pixels.
struct Blob {
  double x = 0, y = 0;
  int pixels = 0;
};
using Match = bool (*)(int r, int g, int b);
Blob Find(int width, int height, const std::vector<uint8_t>& rgb, Match match, int x0 = 0,
          int x1 = -1) {
  Blob b;
  for (int y = 0; y < height; ++y)
    for (int x = x0; x < (x1 < 0 ? width : x1); ++x) {
      const uint8_t* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
      if (!match(p[0], p[1], p[2])) continue;
      b.x += x;
      b.y += y;
      ++b.pixels;
    }
  if (b.pixels > 0) b.x /= b.pixels, b.y /= b.pixels;
  return b;
}
bool Red(int r, int g, int b) { return r > 150 && g < 90 && b < 90; }
bool Blue(int r, int g, int b) { return b > 150 && r < 90 && g < 90; }

// Where the world point (x, y) should be in a top-down image of a
// MarkerWorld, from where its two markers are: they sit at (-2, -1.5) and
// (2, 1.5), so the image's centre is between them and the north-east one
// is at (2, 1.5).
struct Frame {
  Blob sw, ne;
  double X(double x) const { return (sw.x + ne.x) / 2 + x / 2 * (ne.x - sw.x) / 2; }
  double Y(double y) const { return (sw.y + ne.y) / 2 + y / 1.5 * (ne.y - sw.y) / 2; }
};
Frame Markers(int width, int height, const std::vector<uint8_t>& rgb) {
  Frame f{Find(width, height, rgb, Blue, 0, width / 2), Find(width, height, rgb, Blue, width / 2)};
  EXPECT_GT(f.sw.pixels, 4);
  EXPECT_GT(f.ne.pixels, 4);
  EXPECT_GT(f.ne.x, f.sw.x + width / 2) << "east to the right";
  EXPECT_LT(f.ne.y, f.sw.y - height / 2) << "north up";
  return f;
}

// A scene seen from above: blue markers at (-2, -1.5) and (2, 1.5), and a
// red box that starts at (x0, 0.75) and moves `speed` m along +x each step
// (its script). `extra` is more of the world file's `objects:` list.
std::filesystem::path MarkerWorld(const std::string& name, double x0, double speed,
                                  const std::string& extra = "",
                                  const std::string& time_step = "0.1") {
  const std::filesystem::path dir = FreshTempDir("video_cli", name);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: " << time_step << "}\n"
      << "objects:\n"
      << "  - {name: sw, type: shape, shape: box, size: [0.2, 0.2, 0.2], position: [-2, -1.5, "
         "0.1], color: [0.1, 0.1, 0.9]}\n"
      << "  - {name: ne, type: shape, shape: box, size: [0.2, 0.2, 0.2], position: [2, 1.5, "
         "0.1], color: [0.1, 0.1, 0.9]}\n"
      << "  - {name: mover, type: shape, shape: box, size: [0.3, 0.3, 0.2], position: [" << x0
      << ", 0.75, 0.1], color: [0.9, 0.1, 0.1], script: mover.lua}\n"
      << extra;
  std::ofstream(dir / "mover.lua") << "local self\n"
                                      "function sysCall_init() self = sim.getObject('.') end\n"
                                      "function sysCall_actuation()\n"
                                      "  local p = sim.getObjectPosition(self, -1)\n"
                                      "  p[1] = p[1] + "
                                   << speed << "\n  sim.setObjectPosition(self, -1, p)\nend\n";
  return dir;
}

nlohmann::json Summary(const std::filesystem::path& out) {
  std::ifstream f(out / "summary.json");
  return nlohmann::json::parse(f);
}

std::vector<Image> DecodeAll(video::VideoReader* reader) {
  std::vector<Image> frames;
  Image frame;
  while (reader->Next(&frame)) frames.push_back(frame);
  return frames;
}

TEST(VideoCli, SnapshotsEveryNStepsArePngsOfTheArenaWithTheBoxWhereItIs) {
  const auto dir = MarkerWorld("snapshots", 1.0, 0);
  const auto out = dir / "out";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 10 --snapshot-every 5 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(out / "snapshots"))
    files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files,
            (std::vector<std::string>{"step_000000.png", "step_000005.png", "step_000010.png"}));
  const paint::RgbImage png = paint::ReadPng(out / "snapshots" / "step_000010.png");
  ASSERT_EQ(png.width, 640);
  ASSERT_EQ(png.height, 480);
  // The red box at (1, 0.75): halfway from the centre to the north-east marker.
  const Frame f = Markers(png.width, png.height, png.rgb);
  const Blob red = Find(png.width, png.height, png.rgb, Red);
  ASSERT_GT(red.pixels, 100);
  EXPECT_NEAR(red.x, f.X(1), 2);
  EXPECT_NEAR(red.y, f.Y(0.75), 2);
  // summary.json lists them.
  int listed = 0;
  const nlohmann::json summary = Summary(out);
  for (const auto& o : summary["outputs"])
    if (o["kind"] == "snapshot") {
      ++listed;
      EXPECT_TRUE(std::filesystem::exists(out / o["path"].get<std::string>())) << o;
    }
  EXPECT_EQ(listed, 3);
}

// Out of memory while the video is drawn and encoded, at limits where it
// ran out in different places: the recorder's thread let std::bad_alloc
// escape (std::terminate, exit 134), and x264, failed once, was flushed
// at the end and crashed (exit 139). Each ends with a message now, or
// runs (or glibc itself aborts, which nothing can catch: run_program.h).
// Not under AddressSanitizer (ulimit -v stops it before main).
TEST(VideoCli, RunningOutOfMemoryWhileRecordingVideoEndsWithAMessage) {
  if (kAddressSanitizer) GTEST_SKIP() << "ulimit -v stops ASan builds before main";
  for (const int kb : {520000, 600000}) {
    const std::string out = FreshTempDir("video_cli", "oom").string();
    const testing::CommandResult r = testing::RunCommand(
        testing::AddressSpaceLimit(kb) + SWARMSIM_BINARY + " run " + SWARMSIM_SOURCE_DIR +
        "/worlds/diffusion.yaml --set robots=1000 --steps 40 --threads 2 --quiet --video --out " +
        out);
    if (testing::EndedByGlibcOutOfMemory(r.exit_code, r.output)) continue;
    EXPECT_LT(r.exit_code, 128) << kb << ": " << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << kb << ": " << r.output;
    if (r.exit_code != 0) {
      EXPECT_NE(r.output.find("error: "), std::string::npos) << kb << ": " << r.output;
    }
  }
}

TEST(VideoCli, SnapshotsNeedAnOutputFolder) {
  const auto dir = MarkerWorld("snapshots_no_out", 1.0, 0);
  const auto r =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --snapshot-every 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--snapshot-every"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
}

// A world whose start fails before its first frame (here ODE refuses a
// screw joint moving a dynamic body) left a video of no frames that the
// summary did not list, and an empty snapshots folder.
TEST(VideoCli, AStartThatFailsBeforeTheFirstFrameLeavesNoEmptyVideoOrFolder) {
  const std::filesystem::path dir = FreshTempDir("video_cli", "start_fails");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: ode, time_step: 0.01}\n"
         "objects:\n"
         "  - name: s\n"
         "    type: joint\n"
         "    joint: screw\n"
         "    pitch: 0.01\n"
         "    position: [0, 0, 1]\n"
         "    children: [{name: b, type: shape, shape: box, size: [0.1, 0.1, 0.1], dynamic: "
         "true}]\n";
  const std::filesystem::path out = dir / "out";
  const auto r =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --video " +
                 (out / "v.mp4").string() + " --snapshot-every 1 --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("screw joint"), std::string::npos) << r.output;
  EXPECT_EQ(Summary(out)["status"], "error");
  EXPECT_FALSE(std::filesystem::exists(out / "v.mp4")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out / "snapshots")) << r.output;
  std::filesystem::remove_all(dir);
}

TEST(VideoCli, TheVideoDecodesToAFramePerStepWithTheBoxMovingAcross) {
  const auto dir = MarkerWorld("moving", -1.5, 0.15);
  const auto out = dir / "out";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 20 --video --video-size 320x240 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 0.1 s steps cannot give 30 frames/s: a frame every step, and it says so.
  EXPECT_NE(r.output.find("10 frames per simulated second"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("video 21 frames"), std::string::npos) << "the progress line";
  video::VideoReader reader(out / "video.mp4");
  EXPECT_EQ(reader.codec(), "h264");
  EXPECT_EQ(reader.width(), 320);
  EXPECT_EQ(reader.height(), 240);
  EXPECT_NEAR(reader.fps(), 10, 1e-6);
  const std::vector<Image> frames = DecodeAll(&reader);
  ASSERT_EQ(frames.size(), 21u) << "steps 0 to 20";
  // Frame k shows the box after k steps, at x = -1.5 + 0.15 k.
  for (int k : {0, 10, 20}) {
    const Image& image = frames[k];
    const Frame f = Markers(image.width, image.height, image.rgb);
    const Blob red = Find(image.width, image.height, image.rgb, Red);
    ASSERT_GT(red.pixels, 20) << "frame " << k;
    EXPECT_NEAR(red.x, f.X(-1.5 + 0.15 * k), 2) << "frame " << k;
    EXPECT_NEAR(red.y, f.Y(0.75), 2) << "frame " << k;
  }
  // summary.json lists the video.
  bool listed = false;
  const nlohmann::json summary = Summary(out);
  for (const auto& o : summary["outputs"])
    if (o["kind"] == "video") listed = o["path"] == "video.mp4";
  EXPECT_TRUE(listed);
}

TEST(VideoCli, AFrameRateTheTimeStepAllowsIsKeptAndAFileGoesWhereItIsNamed) {
  // 0.01 s steps at 25 frames/s: a frame every 4 steps.
  const auto dir = MarkerWorld("fps", 0, 0, "", "0.01");
  const auto file = dir / "clip.mp4";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 40 --video " +
                            file.string() + " --video-fps 25 --video-size 160x120 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;
  video::VideoReader reader(file);
  EXPECT_NEAR(reader.fps(), 25, 1e-6);
  EXPECT_EQ(DecodeAll(&reader).size(), 11u) << "steps 0, 4, ..., 40";
}

TEST(VideoCli, ACameraGivesTheViewAtItsResolutionRoundedToEvenForVideo) {
  // A camera 3 m west of the red box, looking east at it.
  const auto dir = MarkerWorld("camera", 1.0, 0,
                               "  - {name: cam, type: camera, position: [-2, 0.75, 0.1], "
                               "resolution: [161, 121], fov_deg: 40}\n");
  const auto out = dir / "out";
  const auto r =
      RunProgram("run " + (dir / "world.yaml").string() +
                 " --steps 4 --snapshot-every 4 --video --camera /cam --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("162x122"), std::string::npos) << "the note: " << r.output;
  const paint::RgbImage png = paint::ReadPng(out / "snapshots" / "step_000004.png");
  EXPECT_EQ(png.width, 162);
  EXPECT_EQ(png.height, 122);
  const Blob red = Find(png.width, png.height, png.rgb, Red);
  ASSERT_GT(red.pixels, 20);
  EXPECT_NEAR(red.x, png.width / 2.0, 3) << "straight ahead";
  video::VideoReader reader(out / "video.mp4");
  EXPECT_EQ(reader.width(), 162);
  EXPECT_EQ(reader.height(), 122);
  EXPECT_EQ(DecodeAll(&reader).size(), 5u);
}

TEST(VideoCli, AVisionSensorsSnapshotsDrawItsFloorAndBackgroundAsItSees) {
  // A sensor that sees no floor, on a black background, looking at the red box.
  const auto dir = MarkerWorld("sensor", 1.0, 0,
                               "  - {name: eye, type: vision_sensor, position: [-2, 0.75, 0.1], "
                               "resolution: [64, 48], fov_deg: 40, floor: false}\n");
  const auto out = dir / "out";
  const auto r =
      RunProgram("run " + (dir / "world.yaml").string() +
                 " --steps 1 --snapshot-every 1 --camera /eye --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const paint::RgbImage png = paint::ReadPng(out / "snapshots" / "step_000001.png");
  ASSERT_EQ(png.width, 64);
  ASSERT_EQ(png.height, 48);
  EXPECT_GT(Find(png.width, png.height, png.rgb, Red).pixels, 10);
  const auto black = [](int r, int g, int b) { return r + g + b == 0; };
  EXPECT_GT(Find(png.width, png.height, png.rgb, black).pixels, 64 * 48 / 2)
      << "the background where the floor would be";
}

TEST(VideoCli, ResultsAreTheSameWithAndWithoutVideo) {
  const std::string world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml";
  const auto out = FreshTempDir("video_cli", "hash");
  const auto plain = RunProgram("run " + world + " --set robots=20 --steps 30 --threads 2 --hash");
  const auto filmed =
      RunProgram("run " + world + " --set robots=20 --steps 30 --threads 2 --hash --video " +
                 "--snapshot-every 7 --video-size 160x120 --out " + out.string());
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  ASSERT_EQ(filmed.exit_code, 0) << filmed.output;
  const auto hash = [](const std::string& text) {
    const size_t at = text.find("state-hash: ");
    return at == std::string::npos ? std::string("(none)") : text.substr(at, 28);
  };
  EXPECT_EQ(hash(plain.output), hash(filmed.output));
  EXPECT_NE(hash(plain.output), "(none)");
}

TEST(VideoCli, TheVideoIsTheSameFileAtOneAndTwoThreads) {
  const std::string world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml";
  const auto dir = FreshTempDir("video_cli", "threads");
  std::filesystem::create_directories(dir);
  std::string bytes[2];
  for (int threads : {1, 2}) {
    const auto file = dir / ("t" + std::to_string(threads) + ".mp4");
    const auto r = RunProgram("run " + world + " --set robots=30 --steps 20 --quiet --threads " +
                              std::to_string(threads) + " --video " + file.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream f(file, std::ios::binary);
    bytes[threads - 1].assign(std::istreambuf_iterator<char>(f), {});
  }
  EXPECT_GT(bytes[0].size(), 1000u);
  EXPECT_TRUE(bytes[0] == bytes[1]) << "byte for byte";
}

// Runs a MarkerWorld whose extra dummy signals its own process with
// `signal` at step `at` (its script: os.execute, so --trust-scripts), with
// a 160x120 video into `*out`.
testing::CommandResult RunUntilSignalled(const std::string& name, int at, const std::string& signal,
                                         std::filesystem::path* out) {
  const auto dir =
      MarkerWorld(name, -1.5, 0.01, "  - {name: clock, type: dummy, script: signal.lua}\n");
  std::ofstream(dir / "signal.lua") << "local steps = 0\n"
                                       "function sysCall_actuation()\n"
                                       "  steps = steps + 1\n"
                                       "  if steps == "
                                    << at
                                    << " then\n"
                                       "    local pid = io.open('/proc/self/stat'):read('n')\n"
                                       "    os.execute('kill -"
                                    << signal << " ' .. pid)\n  end\nend\n";
  *out = dir / "out";
  return RunProgram("run " + (dir / "world.yaml").string() +
                    " --steps 100000 --trust-scripts --video --video-size 160x120 --quiet --out " +
                    out->string());
}

TEST(VideoCli, ARunStoppedBySigtermLeavesAPlayableVideoUpToItsLastStep) {
  std::filesystem::path out;
  const auto r = RunUntilSignalled("sigterm", 30, "TERM", &out);
  EXPECT_EQ(r.exit_code, 128 + 15) << r.output;
  const nlohmann::json summary = Summary(out);
  EXPECT_EQ(summary["status"], "interrupted");
  const int64_t steps = summary["steps"];
  EXPECT_GE(steps, 30);
  EXPECT_LT(steps, 100);
  video::VideoReader reader(out / "video.mp4");
  EXPECT_EQ(static_cast<int64_t>(DecodeAll(&reader).size()), steps + 1) << "every frame";
}

TEST(VideoCli, ARunKilledOutrightKeepsTheVideoUpToItsLastWholeSecond) {
  std::filesystem::path out;
  const auto r = RunUntilSignalled("sigkill", 45, "KILL", &out);
  EXPECT_EQ(r.exit_code, 128 + 9) << r.output;
  // A keyframe, and so a fragment on disk, every 10 frames (1 s of video);
  // x264 holds a few frames back.
  video::VideoReader reader(out / "video.mp4");
  const size_t frames = DecodeAll(&reader).size();
  EXPECT_GE(frames, 20u);
  EXPECT_LE(frames, 46u);
}

TEST(VideoCli, AVideoThatCannotBeWrittenMidRunFailsTheRunWithTheOutputsSoFar) {
  // A file size limit (and SIGXFSZ ignored: writes fail with EFBIG) stops
  // the video a few seconds in.
  const auto dir = MarkerWorld("full", -1.5, 0.01);
  const auto out = dir / "out";
  const auto r = testing::RunCommand(
      "ulimit -f 24; trap '' XFSZ; exec " + std::string(SWARMSIM_BINARY) + " run " +
      (dir / "world.yaml").string() + " --steps 100000 --video --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("error: --video: video '"), std::string::npos) << r.output;
  const nlohmann::json summary = Summary(out);
  EXPECT_EQ(summary["status"], "error");
  EXPECT_NE(summary["error"].get<std::string>().find("--video"), std::string::npos);
  EXPECT_LT(summary["steps"].get<int64_t>(), 100000);
  EXPECT_TRUE(std::filesystem::exists(out / "metrics.csv"));
  video::VideoReader reader(out / "video.mp4");  // what reached the disk still plays
  const size_t decoded = DecodeAll(&reader).size();
  EXPECT_GE(decoded, 10u);
  // The summary counts the frames the file holds (it said every frame drawn:
  // 81 where the file held 70).
  std::string description;
  for (const auto& output : summary["outputs"])
    if (output["kind"] == "video") description = output["description"].get<std::string>();
  EXPECT_NE(description.find(", " + std::to_string(decoded) + " frames (of "), std::string::npos)
      << description << " (" << decoded << " frames in the file)";
}

// Proximity sensors' rays (their type's `ray` visual, framework/visual.h)
// are drawn as the viewer draws them: a line along the sensor's +z axis,
// cyan to its full range while it detects nothing, red up to what it
// detects. --no-rays leaves them out.
TEST(VideoCli, SnapshotsDrawProximityRaysUnlessToldNot) {
  // The red box stands at (-0.5, 0.75); `free` looks along +x at y = -0.75
  // and sees nothing in its 2 m, `seeing` looks along +x at y = 0.75 from
  // x = -2 and meets the box's face at x = -0.65, 1.35 m on.
  const auto dir =
      MarkerWorld("rays", -0.5, 0,
                  "  - {name: free, type: proximity_sensor, range: 2, position: [-1, -0.75, 0.1], "
                  "orientation_deg: [0, 90, 0]}\n"
                  "  - {name: seeing, type: proximity_sensor, range: 2, position: [-2, 0.75, 0.1], "
                  "orientation_deg: [0, 90, 0]}\n");
  const auto snapshot = [&](const std::string& flags) {
    const auto out = dir / ("out" + flags);
    const auto r =
        RunProgram("run " + (dir / "world.yaml").string() +
                   " --steps 1 --snapshot-every 1 --quiet --out " + out.string() + " " + flags);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return paint::ReadPng(out / "snapshots" / "step_000001.png");
  };
  const auto cyan = [](int r, int g, int b) { return r < 140 && g > 150 && b > 180; };
  const auto red = [](int r, int g, int b) { return r > 200 && g < 90 && b < 90; };
  // Pixels of `match` in the image's column x, within 2 rows of y.
  const auto near = [](const paint::RgbImage& png, double x, double y, auto match) {
    int n = 0;
    const int column = static_cast<int>(std::lround(x));
    for (int row = static_cast<int>(std::lround(y)) - 2; row <= std::lround(y) + 2; ++row) {
      if (row < 0 || row >= png.height || column < 0 || column >= png.width) continue;
      const uint8_t* p = &png.rgb[(static_cast<size_t>(row) * png.width + column) * 3];
      n += match(p[0], p[1], p[2]);
    }
    return n;
  };
  // Columns of `match` near the ray at world y from x = x0 to x1, every 0.1 m.
  const auto columns = [&](const paint::RgbImage& png, const Frame& f, int x0_dm, int x1_dm,
                           double y, auto match) {
    int n = 0;
    for (int dm = x0_dm; dm <= x1_dm; ++dm) n += near(png, f.X(dm / 10.0), f.Y(y), match) > 0;
    return n;
  };
  const paint::RgbImage with = snapshot("");
  const Frame f = Markers(with.width, with.height, with.rgb);
  // The free ray from just past its start to just before its end, and not past its range.
  EXPECT_EQ(columns(with, f, -8, 8, -0.75, cyan), 17);
  EXPECT_EQ(columns(with, f, 13, 15, -0.75, cyan), 0) << "past its range";
  // The seeing ray is red up to the box, not cyan anywhere.
  EXPECT_EQ(columns(with, f, -18, -8, 0.75, red), 11);
  EXPECT_EQ(columns(with, f, -18, 15, 0.75, cyan), 0);
  // --no-rays: none of it.
  const paint::RgbImage without = snapshot("--no-rays");
  EXPECT_EQ(columns(without, f, -8, 8, -0.75, cyan), 0);
  EXPECT_EQ(columns(without, f, -18, -8, 0.75, red), 0);
  // --no-rays belongs to pictures.
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --no-rays");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--no-rays hides the rays in --snapshot-every or --video"),
            std::string::npos)
      << r.output;
}

TEST(VideoCli, BadVideoOptionsAreNamedAndStopTheRunBeforeItStarts) {
  const auto dir = MarkerWorld("bad", 1.0, 0, "  - {name: overhead, type: camera}\n");
  const std::string world = (dir / "world.yaml").string();
  const auto out = dir / "out";
  for (const std::string size : {"0x0", "100000x100000", "640", "axb"}) {
    const auto r = RunProgram("run " + world + " --steps 2 --video --video-size " + size +
                              " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << size << ": " << r.output;
    EXPECT_NE(r.output.find("--video-size"), std::string::npos) << r.output;
  }
  // An unknown camera: the ones there are.
  auto r = RunProgram("run " + world + " --steps 2 --snapshot-every 1 --camera /nosuch --out " +
                      out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--camera '/nosuch'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("/overhead"), std::string::npos) << "lists the cameras: " << r.output;
  // A name that is no path, and an object that is no camera.
  r = RunProgram("run " + world + " --steps 2 --snapshot-every 1 --camera overhead --out " +
                 out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--camera 'overhead': malformed"), std::string::npos) << r.output;
  r = RunProgram("run " + world + " --steps 2 --snapshot-every 1 --camera /mover --out " +
                 out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("not a camera or vision sensor"), std::string::npos) << r.output;
  // A video where no file can be made: named, and summary.json says so.
  std::filesystem::remove_all(out);
  r = RunProgram("run " + world + " --steps 2 --video " + (dir / "world.yaml/x.mp4").string() +
                 " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--video: cannot write"), std::string::npos) << r.output;
  EXPECT_EQ(Summary(out)["status"], "error");
  r = RunProgram("run " + world + " --steps 2 --video /dev/full");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--video: video '/dev/full'"), std::string::npos) << r.output;
  // --video's FILE is optional: a world file after it is not taken for one.
  r = RunProgram("run --steps 2 --video " + world + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("a world goes before --video"), std::string::npos) << r.output;
  // The world before it and named again as the video: not "put the world before".
  r = RunProgram("run " + world + " --steps 2 --video " + world);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is a .yaml name (a world or model file?): the video would be written "
                          "there; name a FILE.mp4"),
            std::string::npos)
      << r.output;
  // A file there already that is not a video (a script): refused, untouched
  // (the video went over it, exit 0); a video there already is replaced.
  std::ofstream(dir / "bot.lua") << "function sysCall_init() end\n";
  r = RunProgram("run " + world + " --steps 1 --video " + (dir / "bot.lua").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--video: '" + (dir / "bot.lua").string() +
                          "' is a file that is not a video: the video would go over it"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(testing::ReadFile(dir / "bot.lua"), "function sysCall_init() end\n");
  // A name that is not .mp4: an MP4 all the same, and a note says so (.MP4 is no surprise).
  r = RunProgram("run " + world + " --steps 1 --video " + (dir / "film.avi").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: --video " + (dir / "film.avi").string() +
                          ": the video is H.264 in an MP4 container whatever the file is called"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "film.avi"));
  r = RunProgram("run " + world + " --steps 1 --video " + (dir / "film.avi").string());
  EXPECT_EQ(r.exit_code, 0) << "a video over a video: " << r.output;
  r = RunProgram("run " + world + " --steps 1 --video " + (dir / "film.MP4").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("MP4 container"), std::string::npos) << r.output;
  // --video with no file and no folder.
  r = RunProgram("run " + world + " --steps 2 --video");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace swarmsim
