// H.264 video in a fragmented MP4 file, through FFmpeg's libraries, and a
// reader that decodes one back for tests and checks. The libav code is a
// module of its own (libswarmsim_libav.so: video_writer.cc, video_reader.cc;
// libav types stay there), opened on first use of either class
// (libav_loader.h), so a run without video never maps FFmpeg. A module that
// cannot be found or opened is a swarmsim::Error naming the paths tried.
//
// The file is written fragment by fragment (movflags
// frag_keyframe+empty_moov+default_base_moof, a keyframe every second of
// video, each fragment flushed to disk), so a process killed mid-run leaves
// a playable file that lacks at most the last second; Finish() writes the
// rest.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "framework/image.h"

namespace swarmsim::video {

struct VideoSettings {
  int width = 640;  // pixels, even (H.264's 4:2:0 chroma)
  int height = 480;
  double fps = 30;                  // frames per second of video
  int crf = 23;                     // x264's constant quality: lower is better and bigger
  std::string preset = "veryfast";  // x264's speed preset
};

class VideoWriter {
 public:
  // Creates `path` (an existing file is replaced). Throws swarmsim::Error
  // naming the file when it cannot be written or the encoder refuses the
  // settings, or when the libav module cannot be loaded.
  VideoWriter(const std::filesystem::path& path, const VideoSettings& settings);
  ~VideoWriter();  // Finish(), errors ignored
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Appends one frame of settings.width x settings.height. Throws
  // swarmsim::Error on an encoder or write error.
  void Write(const Image& frame);
  // Drains the encoder and completes the file; later calls do nothing.
  // Throws swarmsim::Error on an encoder or write error.
  void Finish();
  int64_t frames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What a video file holds, decoded frame by frame.
class VideoReader {
 public:
  // Throws swarmsim::Error naming the file when it cannot be opened or has
  // no video stream, or when the libav module cannot be loaded.
  explicit VideoReader(const std::filesystem::path& path);
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;

  int width() const;
  int height() const;
  double fps() const;         // the stream's frame rate (frames per second)
  std::string codec() const;  // "h264"
  // Decodes the next frame into *frame (RGB); false after the last one (or
  // where a cut-off file stops).
  bool Next(Image* frame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmsim::video
