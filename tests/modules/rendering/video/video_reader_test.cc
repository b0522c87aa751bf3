// The video reader (modules/rendering/video/video_reader.cc): a file that
// is missing, not a video or cut short is an error naming it (or ends
// early), never a crash; a frame decodes to RGB of the video's size.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/image.h"
#include "modules/rendering/video/video_writer.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim::video {
namespace {

using testing::ErrorOf;
using testing::ReadFile;
using testing::TempDir;

// A 10-frame 32x16 video at 5 frames/s, mid-grey; its path.
std::filesystem::path GreyVideo(const TempDir& dir) {
  const std::filesystem::path file = dir.path() / "grey.mp4";
  VideoSettings settings;
  settings.width = 32;
  settings.height = 16;
  settings.fps = 5;
  VideoWriter writer(file, settings);
  Image frame;
  frame.Resize(32, 16);
  std::fill(frame.rgb.begin(), frame.rgb.end(), uint8_t{128});
  for (int i = 0; i < 10; ++i) writer.Write(frame);
  writer.Finish();
  return file;
}

TEST(VideoReaderTest, DecodesEachFrameToRgbOfTheVideosSize) {
  TempDir dir;
  VideoReader reader(GreyVideo(dir));
  EXPECT_EQ(reader.width(), 32);
  EXPECT_EQ(reader.height(), 16);
  EXPECT_DOUBLE_EQ(reader.fps(), 5);
  Image frame;
  int count = 0;
  while (reader.Next(&frame)) {
    ASSERT_EQ(frame.rgb.size(), 32u * 16u * 3u);
    EXPECT_NEAR(frame.Pixel(7, 9)[1], 128, 6);
    ++count;
  }
  EXPECT_EQ(count, 10);
  EXPECT_FALSE(reader.Next(&frame));  // and stays at the end
}

TEST(VideoReaderTest, AMissingFileOrOneWithoutVideoIsAnErrorNamingIt) {
  TempDir dir;
  const std::string missing = (dir.path() / "none.mp4").string();
  EXPECT_CONTAINS(ErrorOf([&] { VideoReader r(missing); }), "video '" + missing + "': cannot open");
  const std::filesystem::path text = dir.path() / "notes.mp4";
  std::ofstream(text) << "this is not a video, only some words in a file\n";
  const std::string error = ErrorOf([&] { VideoReader r(text); });
  EXPECT_CONTAINS(error, "video '" + text.string() + "'");
}

// Every cut of a good file: an error naming it, or fewer frames; never a
// crash.
TEST(VideoReaderTest, ACutOffFileEndsEarlyOrIsAnError) {
  TempDir dir;
  const std::string bytes = ReadFile(GreyVideo(dir));
  ASSERT_GT(bytes.size(), 100u);
  const std::filesystem::path cut = dir.path() / "cut.mp4";
  for (size_t length = 0; length < bytes.size(); length += bytes.size() / 17 + 1) {
    std::ofstream(cut, std::ios::binary | std::ios::trunc).write(bytes.data(), length);
    int count = 0;
    const std::string error = ErrorOf([&] {
      VideoReader reader(cut);
      Image frame;
      while (reader.Next(&frame)) ++count;
    });
    if (!error.empty()) {
      EXPECT_CONTAINS(error, "video '" + cut.string() + "'");
    }
    EXPECT_LE(count, 10) << "cut at " << length;
  }
}

}  // namespace
}  // namespace swarmsim::video
