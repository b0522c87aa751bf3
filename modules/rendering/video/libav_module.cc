// The libav module's entry point (libav_module.h): the one symbol
// libswarmsim_libav.so exports.
#include "modules/rendering/video/libav_module.h"

namespace swarmsim::video {

// video_writer.cc and video_reader.cc.
FrameEncoder* OpenLibavEncoder(const std::string& path, const VideoSettings& settings,
                               std::string* error);
FrameDecoder* OpenLibavDecoder(const std::string& path, std::string* error);

}  // namespace swarmsim::video

// The table as framework/shared_library.h's LoadOwnLibrary takes it.
extern "C" __attribute__((visibility("default"))) const void* swarmsim_libav_module() {
  static const swarmsim::video::LibavModule module{swarmsim::video::kLibavModuleVersion,
                                                   swarmsim::video::OpenLibavEncoder,
                                                   swarmsim::video::OpenLibavDecoder};
  return &module;
}
