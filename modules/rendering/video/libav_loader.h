// Finding and opening the libav module (libav_module.h) on first use of
// VideoWriter or VideoReader, so that a run without video never maps
// FFmpeg's libraries (framework/shared_library.h says where it is looked for).
#pragma once

#include <filesystem>
#include <vector>

#include "modules/rendering/video/libav_module.h"

namespace swarmsim::video {

// The environment variable naming the module's file: when set (and not
// empty), the only place looked at.
inline constexpr const char* kLibavModuleVariable = "SWARMSIM_LIBAV_MODULE";

// Where the module is looked for, in order (CandidatesOf).
std::vector<std::filesystem::path> LibavModuleCandidates();

// Opens the first of `candidates` that is a libav module of this build's
// version (LoadOwnLibrary). Throws swarmsim::Error naming each path tried and
// why it failed.
const LibavModule& LoadLibavModule(const std::vector<std::filesystem::path>& candidates);

// LoadLibavModule(LibavModuleCandidates()), once per process: a failure is
// kept and thrown again at each call.
const LibavModule& Libav();

}  // namespace swarmsim::video
