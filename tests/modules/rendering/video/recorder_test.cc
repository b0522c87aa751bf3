// The recorder module (modules/rendering/video/recorder.cc) through a World:
// PNG snapshots every N steps (step 0 too) and an H.264 video at the frame
// rate the time step allows, listed as outputs; settings it cannot meet are
// errors naming the `swarmsim run` option, or notes.
#include "modules/rendering/video/recorder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/image.h"
#include "modules/rendering/objects.h"
#include "modules/rendering/video/video_writer.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim::video {
namespace {

using testing::ErrorOf;
using testing::ModuleWorld;
using testing::TempDir;

// A world with a box, recorded by `settings`; runs `steps` steps and
// finishes the recording (as the end of a run does).
std::vector<OutputFile> Record(ModuleWorld* w, const RecorderSettings& settings, int steps) {
  w->Box("box", {}, {{0, 0, 0.1}, {}}, {0.2, 0.2, 0.2});
  w->world().AddModule("recorder", &settings);
  EXPECT_EQ(w->Run(steps), "");
  w->world().WriteOutputs(settings.out_dir);
  return w->world().ListOutputs();
}

TEST(RecorderTest, FramePeriodIsTheNearestWholeNumberOfSteps) {
  EXPECT_EQ(FramePeriod(30, 0.1), 1);  // at most one frame a step
  EXPECT_EQ(FramePeriod(10, 0.1), 1);
  EXPECT_EQ(FramePeriod(2, 0.1), 5);
  EXPECT_EQ(FramePeriod(3, 0.1), 3);  // 3.33 steps
  EXPECT_EQ(FramePeriod(0, 0.1), 1);
  EXPECT_EQ(FramePeriod(1e-300, 1), 1000000000000000);
}

TEST(RecorderTest, SnapshotsEveryNStepsFromTheStart) {
  TempDir dir;
  ModuleWorld w;
  RecorderSettings settings;
  settings.out_dir = dir.path();
  settings.snapshot_every = 2;
  settings.width = 40;
  settings.height = 30;
  const std::vector<OutputFile> outputs = Record(&w, settings, 5);
  std::vector<std::string> paths;
  for (const OutputFile& f : outputs) paths.push_back(f.path);
  EXPECT_EQ(paths,
            (std::vector<std::string>{"snapshots/step_000000.png", "snapshots/step_000002.png",
                                      "snapshots/step_000004.png"}));
  for (const std::string& p : paths) {
    ASSERT_TRUE(std::filesystem::exists(dir.path() / p)) << p;
    const std::string bytes = testing::ReadFile(dir.path() / p);
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
  }
  EXPECT_EQ(outputs[1].description, "step 2, the arena seen from above");
}

// 4 frames per simulated second at 0.1 s steps: a frame every 3 steps
// (3.33 frames/s), said in a note; the video holds the frames of steps 0,
// 3, 6 and 9.
TEST(RecorderTest, AVideoGetsAFrameEveryFewStepsAndSaysItsRate) {
  TempDir dir;
  ModuleWorld w;
  RecorderSettings settings;
  settings.out_dir = dir.path();
  settings.video = dir.path() / "run.mp4";
  settings.width = 64;
  settings.height = 48;
  settings.video_fps = 4;
  w.Box("box", {}, {{0, 0, 0.1}, {}}, {0.2, 0.2, 0.2});
  auto* recorder = dynamic_cast<Recorder*>(w.world().AddModule("recorder", &settings));
  ASSERT_NE(recorder, nullptr);
  ASSERT_EQ(recorder->notes().size(), 1u);
  EXPECT_EQ(recorder->notes()[0],
            "--video-fps 4: with a time step of 0.1 s the video gets a frame every 3 steps, 3.33 "
            "frames per simulated second (it plays in real time)");
  ASSERT_EQ(w.Run(10), "");
  w.world().WriteOutputs(dir.path());
  const std::vector<OutputFile> outputs = w.world().ListOutputs();
  ASSERT_EQ(outputs.size(), 1u);
  EXPECT_EQ(outputs[0].kind, "video");
  EXPECT_EQ(outputs[0].path, "run.mp4");
  EXPECT_EQ(outputs[0].description,
            "H.264 64x48, 3.33 frames/s, 4 frames, the arena seen from above");
  VideoReader reader(settings.video);
  EXPECT_EQ(reader.width(), 64);
  Image frame;
  int frames = 0;
  while (reader.Next(&frame)) ++frames;
  EXPECT_EQ(frames, 4);
}

TEST(RecorderTest, AnOddVideoSizeIsRoundedUpWithANote) {
  TempDir dir;
  ModuleWorld w;
  RecorderSettings settings;
  settings.out_dir = dir.path();
  settings.video = dir.path() / "odd.mp4";
  settings.width = 33;
  settings.height = 21;
  settings.video_fps = 10;
  auto* recorder = dynamic_cast<Recorder*>(w.world().AddModule("recorder", &settings));
  ASSERT_NE(recorder, nullptr);
  ASSERT_EQ(recorder->notes().size(), 1u);
  EXPECT_EQ(recorder->notes()[0], "H.264 takes even sizes: frames are 34x22, not 33x21");
}

TEST(RecorderTest, SettingsItCannotMeetAreErrorsNamingTheOption) {
  TempDir dir;
  const auto error_of = [&](RecorderSettings settings) {
    ModuleWorld w;
    w.Box("box", {}, {}, {0.2, 0.2, 0.2});
    return ErrorOf([&] { w.world().AddModule("recorder", &settings); });
  };
  RecorderSettings no_out;
  no_out.snapshot_every = 5;
  EXPECT_EQ(error_of(no_out),
            "--snapshot-every writes DIR/snapshots/step_NNNNNN.png and needs --out DIR");
  RecorderSettings camera;
  camera.out_dir = dir.path();
  camera.snapshot_every = 1;
  camera.camera = "/box";
  EXPECT_CONTAINS(error_of(camera),
                  "--camera '/box': '/box' is a shape, not a camera or vision "
                  "sensor; this world has no camera or vision sensor");
  RecorderSettings fps;
  fps.out_dir = dir.path();
  fps.video = dir.path() / "v.mp4";
  // Zero, a frame lasting 10^9 s (FFmpeg refused it after the run), infinity.
  for (const double bad : {0.0, 1e-9, static_cast<double>(INFINITY)}) {
    fps.video_fps = bad;
    EXPECT_CONTAINS(error_of(fps),
                    "--video-fps must be from 0.001 to 10000 frames per simulated second, got ");
  }
  RecorderSettings nowhere;
  nowhere.out_dir = dir.path();
  nowhere.video = dir.path() / "no" / "such" / "v.mp4";
  EXPECT_CONTAINS(error_of(nowhere), "--video: cannot write '");
  ModuleWorld w;
  EXPECT_EQ(ErrorOf([&] { w.world().AddModule("recorder", nullptr); }),
            "the recorder module needs its settings");
}

// The camera's own resolution, and the scene's cameras listed when the one
// asked for is not there.
TEST(RecorderTest, ACamerasViewAtItsResolutionOrTheListOfCameras) {
  TempDir dir;
  ModuleWorld w;
  rendering::CameraRow camera;
  camera.lens.width = 50;
  camera.lens.height = 40;
  w.Add("camera", "top", {}, {{0, 0, 3}, {}}, &camera);
  RecorderSettings missing;
  missing.out_dir = dir.path();
  missing.snapshot_every = 1;
  missing.camera = "/side";
  EXPECT_CONTAINS(ErrorOf([&] { w.world().AddModule("recorder", &missing); }),
                  "its cameras and vision sensors: /top");
  RecorderSettings settings = missing;
  settings.camera = "/top";
  const std::vector<OutputFile> outputs = Record(&w, settings, 0);
  ASSERT_EQ(outputs.size(), 1u);
  EXPECT_EQ(outputs[0].description, "step 0, camera /top");
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "snapshots" / "step_000000.png"));
}

}  // namespace
}  // namespace swarmsim::video
