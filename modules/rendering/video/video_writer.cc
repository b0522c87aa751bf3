// The H.264 writer inside the libav module (libav_module.h): the encoder
// behind VideoWriter (video_writer.h).
#include "modules/rendering/video/libav_module.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
}

#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

namespace swarmsim::video {

namespace {

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// RGB to 4:2:0 YUV, BT.601 limited range (swscale's default, in 8-bit
// fixed point), chroma from each 2x2 block's mean. A third of the time
// swscale takes for RGB24 input, which goes through its general scaler.
void ToYuv420(const Image& image, uint8_t* const plane[], const int stride[]) {
  const int w = image.width, h = image.height;
  for (int y = 0; y < h; ++y) {
    const uint8_t* rgb = image.Pixel(0, y);
    uint8_t* luma = plane[0] + static_cast<ptrdiff_t>(y) * stride[0];
    for (int x = 0; x < w; ++x, rgb += 3)
      luma[x] = static_cast<uint8_t>((66 * rgb[0] + 129 * rgb[1] + 25 * rgb[2] + 128 + 4096) >> 8);
  }
  for (int y = 0; y < h / 2; ++y) {
    const uint8_t* top = image.Pixel(0, 2 * y);
    const uint8_t* bottom = image.Pixel(0, 2 * y + 1);
    uint8_t* u = plane[1] + static_cast<ptrdiff_t>(y) * stride[1];
    uint8_t* v = plane[2] + static_cast<ptrdiff_t>(y) * stride[2];
    for (int x = 0; x < w / 2; ++x, top += 6, bottom += 6) {
      const int r = top[0] + top[3] + bottom[0] + bottom[3];  // 4 x the mean
      const int g = top[1] + top[4] + bottom[1] + bottom[4];
      const int b = top[2] + top[5] + bottom[2] + bottom[5];
      u[x] = static_cast<uint8_t>((-38 * r - 74 * g + 112 * b + 512 + 131072) >> 10);
      v[x] = static_cast<uint8_t>((112 * r - 94 * g - 18 * b + 512 + 131072) >> 10);
    }
  }
}

class LibavEncoder final : public FrameEncoder {
 public:
  // Throws std::runtime_error naming the file.
  LibavEncoder(const std::string& path, const VideoSettings& settings);
  ~LibavEncoder() override;

  std::string Write(const Image& image) override;
  std::string Finish() override;
  int64_t frames() const override { return frames_; }

 private:
  [[noreturn]] void Fail(const std::string& what, int code) const {
    throw std::runtime_error("video '" + name_ + "': " + what + ": " + AvError(code));
  }
  // Sends `f` (null: the end) to the encoder and writes what comes out.
  void Encode(const AVFrame* f);
  void Open(const VideoSettings& settings);  // the constructor's work; throws
  void Free();                               // what Open allocated, as far as it got

  std::string name_;  // the file, for messages
  VideoSettings settings_;
  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;
  AVStream* stream_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  int64_t frames_ = 0;
  bool finished_ = false;
  bool broken_ = false;  // the encoder failed: not used again
};

LibavEncoder::~LibavEncoder() { Free(); }

void LibavEncoder::Free() {
  av_packet_free(&packet_);
  av_frame_free(&frame_);
  avcodec_free_context(&codec_);
  if (format_ != nullptr) {
    if (format_->pb != nullptr) avio_closep(&format_->pb);
    avformat_free_context(format_);
    format_ = nullptr;
  }
}

void LibavEncoder::Encode(const AVFrame* f) {
  // An encoder that failed once is not asked again: x264 out of memory
  // left its state half updated, and the end's flush crashed in it.
  if (broken_) throw std::runtime_error("video '" + name_ + "': the H.264 encoder failed earlier");
  int rc = avcodec_send_frame(codec_, f);
  if (rc < 0) {
    broken_ = true;
    Fail("the H.264 encoder failed", rc);
  }
  for (;;) {
    rc = avcodec_receive_packet(codec_, packet_);
    if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
    if (rc < 0) {
      broken_ = true;
      Fail("the H.264 encoder failed", rc);
    }
    av_packet_rescale_ts(packet_, codec_->time_base, stream_->time_base);
    packet_->stream_index = stream_->index;
    rc = av_interleaved_write_frame(format_, packet_);  // takes the packet's data
    if (rc < 0) Fail("cannot write", rc);
  }
}

LibavEncoder::LibavEncoder(const std::string& path, const VideoSettings& settings)
    : name_(path), settings_(settings) {
  try {
    Open(settings);
  } catch (...) {
    Free();  // no destructor runs for a constructor that throws
    throw;
  }
}

void LibavEncoder::Open(const VideoSettings& settings) {
  av_log_set_level(AV_LOG_ERROR);  // no banner or per-file statistics on stderr

  int rc = avformat_alloc_output_context2(&format_, nullptr, "mp4", name_.c_str());
  if (rc < 0 || format_ == nullptr) Fail("cannot make an MP4 muxer", rc);
  const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
  if (encoder == nullptr) encoder = avcodec_find_encoder(AV_CODEC_ID_H264);
  if (encoder == nullptr)
    throw std::runtime_error("video '" + name_ +
                             "': this FFmpeg has no H.264 encoder (Debian's libavcodec59 has "
                             "libx264)");
  stream_ = avformat_new_stream(format_, nullptr);
  codec_ = avcodec_alloc_context3(encoder);
  frame_ = av_frame_alloc();
  packet_ = av_packet_alloc();
  if (stream_ == nullptr || codec_ == nullptr || frame_ == nullptr || packet_ == nullptr)
    throw std::runtime_error("video '" + name_ + "': out of memory");

  // The encoder: 4:2:0, a keyframe (and so a fragment) every second.
  const AVRational rate = av_d2q(settings.fps, 100000);
  codec_->width = settings.width;
  codec_->height = settings.height;
  codec_->pix_fmt = AV_PIX_FMT_YUV420P;
  codec_->time_base = av_inv_q(rate);
  codec_->framerate = rate;
  codec_->gop_size = std::max(1, static_cast<int>(std::lround(settings.fps)));
  codec_->thread_count = 1;  // the recorder's own thread; the simulation has the cores
  codec_->color_range = AVCOL_RANGE_MPEG;
  codec_->colorspace = AVCOL_SPC_SMPTE170M;  // ToYuv420's matrix (BT.601), as players assume
  codec_->color_primaries = AVCOL_PRI_SMPTE170M;
  codec_->color_trc = AVCOL_TRC_SMPTE170M;
  if (format_->oformat->flags & AVFMT_GLOBALHEADER) codec_->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(codec_->priv_data, "preset", settings.preset.c_str(), 0);
  av_opt_set_int(codec_->priv_data, "crf", settings.crf, 0);
  rc = avcodec_open2(codec_, encoder, nullptr);
  if (rc < 0)
    Fail("the H.264 encoder refused " + std::to_string(settings.width) + "x" +
             std::to_string(settings.height),
         rc);
  rc = avcodec_parameters_from_context(stream_->codecpar, codec_);
  if (rc < 0) Fail("cannot set up the stream", rc);
  stream_->time_base = codec_->time_base;
  stream_->avg_frame_rate = rate;
  stream_->r_frame_rate = rate;

  // The file: fragmented, each fragment flushed as it is written.
  rc = avio_open(&format_->pb, name_.c_str(), AVIO_FLAG_WRITE);
  if (rc < 0) throw std::runtime_error("cannot write '" + name_ + "': " + AvError(rc));
  format_->flags |= AVFMT_FLAG_FLUSH_PACKETS;
  AVDictionary* options = nullptr;
  av_dict_set(&options, "movflags", "frag_keyframe+empty_moov+default_base_moof", 0);
  rc = avformat_write_header(format_, &options);
  av_dict_free(&options);
  if (rc < 0) Fail("cannot write the MP4 header", rc);
  avio_flush(format_->pb);
  if (format_->pb->error < 0)
    throw std::runtime_error("cannot write '" + name_ + "': " + AvError(format_->pb->error));

  frame_->format = AV_PIX_FMT_YUV420P;
  frame_->width = settings.width;
  frame_->height = settings.height;
  frame_->color_range = AVCOL_RANGE_MPEG;
  frame_->colorspace = AVCOL_SPC_SMPTE170M;
  rc = av_frame_get_buffer(frame_, 0);
  if (rc < 0) Fail("out of memory for a frame", rc);
}

std::string LibavEncoder::Write(const Image& image) try {
  if (finished_) return "video '" + name_ + "': already finished";
  if (image.width != settings_.width || image.height != settings_.height)
    return "video '" + name_ + "': a " + std::to_string(image.width) + "x" +
           std::to_string(image.height) + " frame in a " + std::to_string(settings_.width) + "x" +
           std::to_string(settings_.height) + " video";
  const int rc = av_frame_make_writable(frame_);  // the encoder may still hold the last one
  if (rc < 0) Fail("out of memory for a frame", rc);
  ToYuv420(image, frame_->data, frame_->linesize);
  frame_->pts = frames_++;
  Encode(frame_);
  return "";
} catch (const std::exception& e) {
  return e.what();
}

std::string LibavEncoder::Finish() try {
  if (finished_) return "";
  finished_ = true;
  // After a failure, the frames encoded before it, in a file that ends
  // properly (the encoder's own delayed frames are lost with it).
  if (!broken_) Encode(nullptr);
  int rc = av_write_trailer(format_);
  if (rc < 0) Fail("cannot complete the file", rc);
  rc = avio_closep(&format_->pb);
  if (rc < 0) Fail("cannot complete the file", rc);
  return "";
} catch (const std::exception& e) {
  return e.what();
}

}  // namespace

FrameEncoder* OpenLibavEncoder(const std::string& path, const VideoSettings& settings,
                               std::string* error) {
  try {
    return new LibavEncoder(path, settings);
  } catch (const std::exception& e) {
    *error = e.what();
    return nullptr;
  }
}

}  // namespace swarmsim::video
