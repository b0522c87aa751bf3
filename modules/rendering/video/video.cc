// VideoWriter and VideoReader (video_writer.h): checks of what they are given,
// then the libav module's encoder and decoder (libav_module.h), opened on
// first use (libav_loader.h).
#include <memory>
#include <string>

#include "framework/error.h"
#include "modules/rendering/video/libav_loader.h"
#include "modules/rendering/video/libav_module.h"
#include "modules/rendering/video/video_writer.h"

namespace swarmsim::video {

namespace {

// Throws swarmsim::Error(what) unless `what` is empty.
void ThrowIf(const std::string& what) {
  if (!what.empty()) throw Error(what);
}

}  // namespace

struct VideoWriter::Impl {
  std::unique_ptr<FrameEncoder> encoder;
};

VideoWriter::VideoWriter(const std::filesystem::path& path, const VideoSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  const std::string name = path.string();
  if (settings.width <= 0 || settings.height <= 0 || settings.width % 2 != 0 ||
      settings.height % 2 != 0)
    throw Error("video '" + name + "': " + std::to_string(settings.width) + "x" +
                std::to_string(settings.height) + " is not a size H.264 takes (even, > 0)");
  if (!(settings.fps > 0)) throw Error("video '" + name + "': the frame rate must be > 0");
  std::string error;
  impl_->encoder.reset(Libav().open_encoder(name, settings, &error));
  if (impl_->encoder == nullptr) throw Error(error);
}

VideoWriter::~VideoWriter() {
  // The file is cut off on an error; nothing more to do here.
  if (impl_->encoder != nullptr) impl_->encoder->Finish();
}

void VideoWriter::Write(const Image& frame) { ThrowIf(impl_->encoder->Write(frame)); }

void VideoWriter::Finish() { ThrowIf(impl_->encoder->Finish()); }

int64_t VideoWriter::frames() const { return impl_->encoder->frames(); }

struct VideoReader::Impl {
  std::unique_ptr<FrameDecoder> decoder;
};

VideoReader::VideoReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  std::string error;
  impl_->decoder.reset(Libav().open_decoder(path.string(), &error));
  if (impl_->decoder == nullptr) throw Error(error);
}

VideoReader::~VideoReader() = default;

int VideoReader::width() const { return impl_->decoder->width(); }
int VideoReader::height() const { return impl_->decoder->height(); }
double VideoReader::fps() const { return impl_->decoder->fps(); }
std::string VideoReader::codec() const { return impl_->decoder->codec(); }

bool VideoReader::Next(Image* frame) {
  bool decoded = false;
  ThrowIf(impl_->decoder->Next(frame, &decoded));
  return decoded;
}

}  // namespace swarmsim::video
