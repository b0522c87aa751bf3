#include "modules/rendering/video/libav_loader.h"

#include <string>

#include "framework/error.h"
#include "framework/shared_library.h"

namespace swarmsim::video {

namespace {

// Set by modules/rendering/video/CMakeLists.txt: the module's file name and
// where this build put it.
#ifndef SWARMSIM_LIBAV_MODULE_NAME
#define SWARMSIM_LIBAV_MODULE_NAME "libswarmsim_libav.so"
#endif
#ifndef SWARMSIM_LIBAV_MODULE_PATH
#define SWARMSIM_LIBAV_MODULE_PATH ""
#endif

const OwnLibrary& LibavLibrary() {
  static const OwnLibrary library{
      SWARMSIM_LIBAV_MODULE_NAME,
      SWARMSIM_LIBAV_MODULE_PATH,
      kLibavModuleVariable,
      kLibavModuleEntry,
      kLibavModuleVersion,
      "videos need swarmsim's libav module (" SWARMSIM_LIBAV_MODULE_NAME
      ", on FFmpeg's libavcodec, libavformat and libswscale: Debian's libavcodec59, "
      "libavformat59 and libswscale6, which tools/setup.sh installs)"};
  return library;
}

}  // namespace

std::vector<std::filesystem::path> LibavModuleCandidates() { return CandidatesOf(LibavLibrary()); }

const LibavModule& LoadLibavModule(const std::vector<std::filesystem::path>& candidates) {
  return *static_cast<const LibavModule*>(LoadOwnLibrary(LibavLibrary(), candidates));
}

const LibavModule& Libav() {
  static const LazyOwnLibrary library(LibavLibrary());
  return *static_cast<const LibavModule*>(library.Get());
}

}  // namespace swarmsim::video
