// The H.264 video writer (modules/rendering/video/video_writer.cc): frames
// written come back from the file (size, rate, count and colours, within
// the codec's loss), a file cut off mid-run still plays up to its last
// fragment, and sizes, frames or files it cannot take are errors naming
// the file.
#include "modules/rendering/video/video_writer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/image.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim::video {
namespace {

using testing::ErrorOf;
using testing::TempDir;

Image Solid(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  Image image;
  image.Resize(w, h);
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    image.rgb[i] = r;
    image.rgb[i + 1] = g;
    image.rgb[i + 2] = b;
  }
  return image;
}

// The mean of one channel.
double Mean(const Image& image, int channel) {
  double sum = 0;
  for (size_t i = channel; i < image.rgb.size(); i += 3) sum += image.rgb[i];
  return sum / (image.rgb.size() / 3);
}

struct Colour {
  uint8_t r, g, b;
};

TEST(VideoWriterTest, FramesComeBackFromTheFile) {
  TempDir dir;
  const std::filesystem::path file = dir.path() / "clip.mp4";
  const std::vector<Colour> colours = {{200, 30, 30}, {30, 200, 30}, {30, 30, 200}};
  VideoSettings settings;
  settings.width = 64;
  settings.height = 48;
  settings.fps = 10;
  {
    VideoWriter writer(file, settings);
    for (int i = 0; i < 30; ++i) {
      const Colour& c = colours[i / 10];
      writer.Write(Solid(64, 48, c.r, c.g, c.b));
    }
    EXPECT_EQ(writer.frames(), 30);
    writer.Finish();
    writer.Finish();  // later calls do nothing
  }
  VideoReader reader(file);
  EXPECT_EQ(reader.width(), 64);
  EXPECT_EQ(reader.height(), 48);
  EXPECT_DOUBLE_EQ(reader.fps(), 10);
  EXPECT_EQ(reader.codec(), "h264");
  Image frame;
  int count = 0;
  while (reader.Next(&frame)) {
    ASSERT_EQ(frame.width, 64);
    ASSERT_EQ(frame.height, 48);
    const Colour& c = colours[count / 10];
    EXPECT_NEAR(Mean(frame, 0), c.r, 8) << "frame " << count;
    EXPECT_NEAR(Mean(frame, 1), c.g, 8) << "frame " << count;
    EXPECT_NEAR(Mean(frame, 2), c.b, 8) << "frame " << count;
    ++count;
  }
  EXPECT_EQ(count, 30);
}

// Never finished (a run killed mid-way): the fragments flushed so far (a
// keyframe, and so a fragment, every second of video) play.
TEST(VideoWriterTest, AnUnfinishedFileStillPlaysItsFragments) {
  TempDir dir;
  const std::filesystem::path file = dir.path() / "cut.mp4";
  VideoSettings settings;
  settings.width = 32;
  settings.height = 32;
  settings.fps = 5;
  auto writer = std::make_unique<VideoWriter>(file, settings);
  for (int i = 0; i < 23; ++i) writer->Write(Solid(32, 32, 128, 128, 128));
  // A copy of the file as it is now, before the destructor finishes it.
  const std::filesystem::path copy = dir.path() / "copy.mp4";
  std::filesystem::copy_file(file, copy);
  writer.reset();
  VideoReader reader(copy);
  Image frame;
  int count = 0;
  while (reader.Next(&frame)) ++count;
  EXPECT_GE(count, 5);  // at least the first second
  EXPECT_LE(count, 23);
}

TEST(VideoWriterTest, WhatItCannotTakeIsAnErrorNamingTheFile) {
  TempDir dir;
  const std::string file = (dir.path() / "bad.mp4").string();
  VideoSettings odd;
  odd.width = 63;
  EXPECT_EQ(ErrorOf([&] { VideoWriter w(file, odd); }),
            "video '" + file + "': 63x480 is not a size H.264 takes (even, > 0)");
  VideoSettings still;
  still.fps = 0;
  EXPECT_EQ(ErrorOf([&] { VideoWriter w(file, still); }),
            "video '" + file + "': the frame rate must be > 0");
  const std::string nowhere = (dir.path() / "missing" / "v.mp4").string();
  EXPECT_CONTAINS(ErrorOf([&] { VideoWriter w(nowhere, VideoSettings{}); }),
                  "cannot write '" + nowhere + "'");
  VideoSettings small;
  small.width = 16;
  small.height = 16;
  VideoWriter writer(file, small);
  EXPECT_EQ(ErrorOf([&] { writer.Write(Solid(32, 16, 0, 0, 0)); }),
            "video '" + file + "': a 32x16 frame in a 16x16 video");
  writer.Finish();
  EXPECT_EQ(ErrorOf([&] { writer.Write(Solid(16, 16, 0, 0, 0)); }),
            "video '" + file + "': already finished");
}

}  // namespace
}  // namespace swarmsim::video
