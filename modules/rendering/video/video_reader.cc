// The decoder inside the libav module (libav_module.h): a video back to RGB
// frames, behind VideoReader (video_writer.h).
#include <exception>
#include <stdexcept>
#include <string>

#include "modules/rendering/video/libav_module.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

namespace swarmsim::video {

namespace {

class LibavDecoder final : public FrameDecoder {
 public:
  // Throws std::runtime_error naming the file.
  explicit LibavDecoder(const std::string& path);
  ~LibavDecoder() override;

  int width() const override { return codec_->width; }
  int height() const override { return codec_->height; }
  double fps() const override { return fps_; }
  std::string codec() const override { return codec_->codec->name; }
  std::string Next(Image* image, bool* decoded) override;

 private:
  void Open();  // the constructor's work; throws
  void Free();  // what Open allocated, as far as it got

  std::string name_;
  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  SwsContext* sws_ = nullptr;
  int stream_ = -1;
  double fps_ = 0;
  bool draining_ = false;  // the file has ended; the decoder gives what it holds
};

LibavDecoder::~LibavDecoder() { Free(); }

void LibavDecoder::Free() {
  sws_freeContext(sws_);
  sws_ = nullptr;
  av_packet_free(&packet_);
  av_frame_free(&frame_);
  avcodec_free_context(&codec_);
  avformat_close_input(&format_);
}

LibavDecoder::LibavDecoder(const std::string& path) : name_(path) {
  try {
    Open();
  } catch (...) {
    Free();  // no destructor runs for a constructor that throws
    throw;
  }
}

void LibavDecoder::Open() {
  av_log_set_level(AV_LOG_ERROR);
  const auto fail = [&](const std::string& what, int rc) {
    char text[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(rc, text, sizeof text);
    throw std::runtime_error("video '" + name_ + "': " + what +
                             (rc < 0 ? std::string(": ") + text : ""));
  };
  int rc = avformat_open_input(&format_, name_.c_str(), nullptr, nullptr);
  if (rc < 0) fail("cannot open", rc);
  rc = avformat_find_stream_info(format_, nullptr);
  if (rc < 0) fail("cannot read", rc);
  const AVCodec* decoder = nullptr;
  stream_ = av_find_best_stream(format_, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (stream_ < 0 || decoder == nullptr) fail("no video stream", stream_);
  const AVStream* s = format_->streams[stream_];
  codec_ = avcodec_alloc_context3(decoder);
  frame_ = av_frame_alloc();
  packet_ = av_packet_alloc();
  if (codec_ == nullptr || frame_ == nullptr || packet_ == nullptr) fail("out of memory", 0);
  rc = avcodec_parameters_to_context(codec_, s->codecpar);
  if (rc < 0) fail("bad stream parameters", rc);
  codec_->thread_count = 1;
  rc = avcodec_open2(codec_, decoder, nullptr);
  if (rc < 0) fail("cannot decode", rc);
  const AVRational rate = s->avg_frame_rate.num > 0 ? s->avg_frame_rate : s->r_frame_rate;
  fps_ = rate.den > 0 ? av_q2d(rate) : 0;
}

std::string LibavDecoder::Next(Image* image, bool* decoded) try {
  *decoded = false;
  for (;;) {
    const int rc = avcodec_receive_frame(codec_, frame_);
    if (rc == 0) break;
    if (rc == AVERROR_EOF || (rc < 0 && rc != AVERROR(EAGAIN))) return "";
    if (draining_) return "";
    // The decoder wants input: the next packet of the stream, or the end.
    bool sent = false;
    while (!sent) {
      if (av_read_frame(format_, packet_) < 0) {  // the end, or where a cut file stops
        draining_ = true;
        avcodec_send_packet(codec_, nullptr);
        sent = true;
      } else {
        if (packet_->stream_index == stream_) {
          avcodec_send_packet(codec_, packet_);  // a damaged packet is skipped
          sent = true;
        }
        av_packet_unref(packet_);
      }
    }
  }
  const int w = frame_->width, h = frame_->height;
  sws_ = sws_getCachedContext(sws_, w, h, static_cast<AVPixelFormat>(frame_->format), w, h,
                              AV_PIX_FMT_RGB24, SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (sws_ == nullptr) return "video '" + name_ + "': no conversion to RGB";
  image->Resize(w, h);
  uint8_t* dst[1] = {image->rgb.data()};
  const int stride[1] = {3 * w};
  sws_scale(sws_, frame_->data, frame_->linesize, 0, h, dst, stride);
  av_frame_unref(frame_);
  *decoded = true;
  return "";
} catch (const std::exception& e) {
  return e.what();
}

}  // namespace

FrameDecoder* OpenLibavDecoder(const std::string& path, std::string* error) {
  try {
    return new LibavDecoder(path);
  } catch (const std::exception& e) {
    *error = e.what();
    return nullptr;
  }
}

}  // namespace swarmsim::video
