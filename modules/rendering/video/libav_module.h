// The seam between swarmsim and its libav module (libswarmsim_libav.so, built
// from video_writer.cc, video_reader.cc and libav_module.cc): FFmpeg's
// libraries and what they pull (some 24 MB of resident memory and 100-odd
// shared libraries) are mapped only when a run writes or reads a video.
// libav_loader.cc finds and opens the module on first use; VideoWriter and
// VideoReader (video_writer.h) call it through this interface. No libav type
// crosses it, and no exception: a call that fails returns what went wrong.
// Both sides come from one build (kLibavModuleVersion guards a stale module).
#pragma once

#include <cstdint>
#include <string>

#include "framework/image.h"
#include "modules/rendering/video/video_writer.h"

namespace swarmsim::video {

// Bumped whenever anything in this file changes.
inline constexpr int kLibavModuleVersion = 1;

// An H.264 encoder writing a fragmented MP4 file (video_writer.h says how).
class FrameEncoder {
 public:
  virtual ~FrameEncoder() = default;
  // Appends one frame of the settings' size. "" or what went wrong.
  virtual std::string Write(const Image& frame) = 0;
  // Drains the encoder and completes the file. "" or what went wrong.
  virtual std::string Finish() = 0;
  virtual int64_t frames() const = 0;  // frames given to the encoder
};

// A video file's decoder.
class FrameDecoder {
 public:
  virtual ~FrameDecoder() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual double fps() const = 0;
  virtual std::string codec() const = 0;
  // Decodes the next frame into *frame and sets *decoded, or clears it after
  // the last frame. "" or what went wrong.
  virtual std::string Next(Image* frame, bool* decoded) = 0;
};

// What the module exports, through kLibavModuleEntry.
struct LibavModule {
  int version = 0;  // kLibavModuleVersion of the module's build
  // A new encoder or decoder (the caller deletes it), or null and *error
  // set. Messages name the file; settings are checked by the caller.
  FrameEncoder* (*open_encoder)(const std::string& path, const VideoSettings& settings,
                                std::string* error) = nullptr;
  FrameDecoder* (*open_decoder)(const std::string& path, std::string* error) = nullptr;
};

// The module's one exported symbol: extern "C" const void* NAME(), the
// module's LibavModule.
inline constexpr const char* kLibavModuleEntry = "swarmsim_libav_module";

}  // namespace swarmsim::video
