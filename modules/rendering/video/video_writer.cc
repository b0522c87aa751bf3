#include "modules/rendering/video/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
}

#include <algorithm>
#include <cmath>

#include "framework/error.h"

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

}  // namespace

struct VideoWriter::Impl {
  std::string name;  // the file, for messages
  VideoSettings settings;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int64_t frames = 0;
  bool finished = false;

  ~Impl() {
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }

  [[noreturn]] void Fail(const std::string& what, int code) const {
    throw Error("video '" + name + "': " + what + ": " + AvError(code));
  }

  // Sends `f` (null: the end) to the encoder and writes what comes out.
  void Encode(const AVFrame* f) {
    int rc = avcodec_send_frame(codec, f);
    if (rc < 0) Fail("the H.264 encoder failed", rc);
    for (;;) {
      rc = avcodec_receive_packet(codec, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
      if (rc < 0) Fail("the H.264 encoder failed", rc);
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      rc = av_interleaved_write_frame(format, packet);  // takes the packet's data
      if (rc < 0) Fail("cannot write", rc);
    }
  }
};

VideoWriter::VideoWriter(const std::filesystem::path& path, const VideoSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& v = *impl_;
  v.name = path.string();
  v.settings = settings;
  if (settings.width <= 0 || settings.height <= 0 || settings.width % 2 != 0 ||
      settings.height % 2 != 0)
    throw Error("video '" + v.name + "': " + std::to_string(settings.width) + "x" +
                std::to_string(settings.height) + " is not a size H.264 takes (even, > 0)");
  if (!(settings.fps > 0)) throw Error("video '" + v.name + "': the frame rate must be > 0");
  av_log_set_level(AV_LOG_ERROR);  // no banner or per-file statistics on stderr

  int rc = avformat_alloc_output_context2(&v.format, nullptr, "mp4", v.name.c_str());
  if (rc < 0 || v.format == nullptr) v.Fail("cannot make an MP4 muxer", rc);
  const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
  if (encoder == nullptr) encoder = avcodec_find_encoder(AV_CODEC_ID_H264);
  if (encoder == nullptr)
    throw Error("video '" + v.name +
                "': this FFmpeg has no H.264 encoder (Debian's libavcodec59 has libx264)");
  v.stream = avformat_new_stream(v.format, nullptr);
  v.codec = avcodec_alloc_context3(encoder);
  v.frame = av_frame_alloc();
  v.packet = av_packet_alloc();
  if (v.stream == nullptr || v.codec == nullptr || v.frame == nullptr || v.packet == nullptr)
    throw Error("video '" + v.name + "': out of memory");

  // The encoder: 4:2:0, a keyframe (and so a fragment) every second.
  const AVRational rate = av_d2q(settings.fps, 100000);
  v.codec->width = settings.width;
  v.codec->height = settings.height;
  v.codec->pix_fmt = AV_PIX_FMT_YUV420P;
  v.codec->time_base = av_inv_q(rate);
  v.codec->framerate = rate;
  v.codec->gop_size = std::max(1, static_cast<int>(std::lround(settings.fps)));
  v.codec->thread_count = 1;  // the recorder's own thread; the simulation has the cores
  v.codec->color_range = AVCOL_RANGE_MPEG;
  v.codec->colorspace = AVCOL_SPC_SMPTE170M;  // ToYuv420's matrix (BT.601), as players assume
  v.codec->color_primaries = AVCOL_PRI_SMPTE170M;
  v.codec->color_trc = AVCOL_TRC_SMPTE170M;
  if (v.format->oformat->flags & AVFMT_GLOBALHEADER) v.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(v.codec->priv_data, "preset", settings.preset.c_str(), 0);
  av_opt_set_int(v.codec->priv_data, "crf", settings.crf, 0);
  rc = avcodec_open2(v.codec, encoder, nullptr);
  if (rc < 0)
    v.Fail("the H.264 encoder refused " + std::to_string(settings.width) + "x" +
               std::to_string(settings.height),
           rc);
  rc = avcodec_parameters_from_context(v.stream->codecpar, v.codec);
  if (rc < 0) v.Fail("cannot set up the stream", rc);
  v.stream->time_base = v.codec->time_base;
  v.stream->avg_frame_rate = rate;
  v.stream->r_frame_rate = rate;

  // The file: fragmented, each fragment flushed as it is written.
  rc = avio_open(&v.format->pb, v.name.c_str(), AVIO_FLAG_WRITE);
  if (rc < 0) throw Error("cannot write '" + v.name + "': " + AvError(rc));
  v.format->flags |= AVFMT_FLAG_FLUSH_PACKETS;
  AVDictionary* options = nullptr;
  av_dict_set(&options, "movflags", "frag_keyframe+empty_moov+default_base_moof", 0);
  rc = avformat_write_header(v.format, &options);
  av_dict_free(&options);
  if (rc < 0) v.Fail("cannot write the MP4 header", rc);
  avio_flush(v.format->pb);
  if (v.format->pb->error < 0)
    throw Error("cannot write '" + v.name + "': " + AvError(v.format->pb->error));

  v.frame->format = AV_PIX_FMT_YUV420P;
  v.frame->width = settings.width;
  v.frame->height = settings.height;
  v.frame->color_range = AVCOL_RANGE_MPEG;
  v.frame->colorspace = AVCOL_SPC_SMPTE170M;
  rc = av_frame_get_buffer(v.frame, 0);
  if (rc < 0) v.Fail("out of memory for a frame", rc);
}

VideoWriter::~VideoWriter() {
  try {
    Finish();
  } catch (const std::exception&) {  // the file is cut off; nothing more to do here
  }
}

void VideoWriter::Write(const Image& image) {
  Impl& v = *impl_;
  if (v.finished) throw Error("video '" + v.name + "': already finished");
  if (image.width != v.settings.width || image.height != v.settings.height)
    throw Error("video '" + v.name + "': a " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " frame in a " + std::to_string(v.settings.width) +
                "x" + std::to_string(v.settings.height) + " video");
  int rc = av_frame_make_writable(v.frame);  // the encoder may still hold the last one
  if (rc < 0) v.Fail("out of memory for a frame", rc);
  ToYuv420(image, v.frame->data, v.frame->linesize);
  v.frame->pts = v.frames++;
  v.Encode(v.frame);
}

void VideoWriter::Finish() {
  Impl& v = *impl_;
  if (v.finished) return;
  v.finished = true;
  v.Encode(nullptr);
  int rc = av_write_trailer(v.format);
  if (rc < 0) v.Fail("cannot complete the file", rc);
  rc = avio_closep(&v.format->pb);
  if (rc < 0) v.Fail("cannot complete the file", rc);
}

int64_t VideoWriter::frames() const { return impl_->frames; }

}  // namespace swarmsim::video
