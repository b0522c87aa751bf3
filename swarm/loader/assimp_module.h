// The seam between swarmsim and its assimp module (libswarmsim_assimp.so,
// built from mesh_assimp.cc): assimp and draco (~3.3 MB resident) are mapped
// only when a world reads a mesh file. mesh.cc reads and checks the file's
// bytes (mesh_check.h), then opens the module on first use
// (framework/shared_library.h says where it is looked for); no assimp type
// and no exception crosses the seam. Both sides come from one build
// (kAssimpModuleVersion guards a stale module).
#pragma once

#include <functional>
#include <string>

#include "swarm/loader/mesh.h"

namespace swarmsim::loader {

// Bumped whenever anything in this file or in MeshCache::Welded changes.
inline constexpr int kAssimpModuleVersion = 2;

// What the module exports, through kAssimpModuleEntry.
struct AssimpModule {
  int version = 0;  // kAssimpModuleVersion of the module's build
  // The triangles of the mesh file `path`, whose checked contents are
  // `bytes` (files beside it, an OBJ's material library, are read from
  // disk), welded into *out. "" or what went wrong, naming the file as
  // `text` ("cannot read mesh file 'text': ..."). `stop_requested` is asked
  // now and then (assimp's progress reports, every 65,536 faces welded):
  // once it says yes, the read is abandoned ("", *out incomplete).
  std::string (*read_mesh)(const std::string& path, const std::string& bytes,
                           const std::string& text, const std::function<bool()>& stop_requested,
                           MeshCache::Welded* out) = nullptr;
};

// The module's one exported symbol: extern "C" const void* NAME(), the
// module's AssimpModule.
inline constexpr const char* kAssimpModuleEntry = "swarmsim_assimp_module";

// The environment variable naming the module's file instead.
inline constexpr const char* kAssimpModuleVariable = "SWARMSIM_ASSIMP_MODULE";

}  // namespace swarmsim::loader
