// Decoding a video back to RGB frames (VideoReader, video_writer.h).
#include <string>

#include "modules/rendering/video/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

#include "framework/error.h"

namespace swarmsim::video {

struct VideoReader::Impl {
  std::string name;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  int stream = -1;
  double fps = 0;
  bool draining = false;  // the file has ended; the decoder gives what it holds

  ~Impl() {
    sws_freeContext(sws);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

VideoReader::VideoReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.name = path.string();
  av_log_set_level(AV_LOG_ERROR);
  const auto fail = [&](const std::string& what, int rc) {
    char text[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(rc, text, sizeof text);
    throw Error("video '" + r.name + "': " + what + (rc < 0 ? std::string(": ") + text : ""));
  };
  int rc = avformat_open_input(&r.format, r.name.c_str(), nullptr, nullptr);
  if (rc < 0) fail("cannot open", rc);
  rc = avformat_find_stream_info(r.format, nullptr);
  if (rc < 0) fail("cannot read", rc);
  const AVCodec* decoder = nullptr;
  r.stream = av_find_best_stream(r.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (r.stream < 0 || decoder == nullptr) fail("no video stream", r.stream);
  const AVStream* s = r.format->streams[r.stream];
  r.codec = avcodec_alloc_context3(decoder);
  r.frame = av_frame_alloc();
  r.packet = av_packet_alloc();
  if (r.codec == nullptr || r.frame == nullptr || r.packet == nullptr) fail("out of memory", 0);
  rc = avcodec_parameters_to_context(r.codec, s->codecpar);
  if (rc < 0) fail("bad stream parameters", rc);
  r.codec->thread_count = 1;
  rc = avcodec_open2(r.codec, decoder, nullptr);
  if (rc < 0) fail("cannot decode", rc);
  const AVRational rate = s->avg_frame_rate.num > 0 ? s->avg_frame_rate : s->r_frame_rate;
  r.fps = rate.den > 0 ? av_q2d(rate) : 0;
}

VideoReader::~VideoReader() = default;

int VideoReader::width() const { return impl_->codec->width; }
int VideoReader::height() const { return impl_->codec->height; }
double VideoReader::fps() const { return impl_->fps; }
std::string VideoReader::codec() const { return impl_->codec->codec->name; }

bool VideoReader::Next(Image* image) {
  Impl& r = *impl_;
  for (;;) {
    const int rc = avcodec_receive_frame(r.codec, r.frame);
    if (rc == 0) break;
    if (rc == AVERROR_EOF || (rc < 0 && rc != AVERROR(EAGAIN))) return false;
    if (r.draining) return false;
    // The decoder wants input: the next packet of the stream, or the end.
    bool sent = false;
    while (!sent) {
      if (av_read_frame(r.format, r.packet) < 0) {  // the end, or where a cut file stops
        r.draining = true;
        avcodec_send_packet(r.codec, nullptr);
        sent = true;
      } else {
        if (r.packet->stream_index == r.stream) {
          avcodec_send_packet(r.codec, r.packet);  // a damaged packet is skipped
          sent = true;
        }
        av_packet_unref(r.packet);
      }
    }
  }
  const int w = r.frame->width, h = r.frame->height;
  r.sws = sws_getCachedContext(r.sws, w, h, static_cast<AVPixelFormat>(r.frame->format), w, h,
                               AV_PIX_FMT_RGB24, SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (r.sws == nullptr) throw Error("video '" + r.name + "': no conversion to RGB");
  image->Resize(w, h);
  uint8_t* dst[1] = {image->rgb.data()};
  const int stride[1] = {3 * w};
  sws_scale(r.sws, r.frame->data, r.frame->linesize, 0, h, dst, stride);
  av_frame_unref(r.frame);
  return true;
}

}  // namespace swarmsim::video
