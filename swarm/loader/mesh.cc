// MeshCache (mesh.h): files read and checked here, their triangles read by
// the assimp module (assimp_module.h, mesh_assimp.cc), opened on the first
// mesh file.
#include "swarm/loader/mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <utility>

#include "framework/display_path.h"
#include "framework/error.h"
#include "framework/shared_library.h"
#include "swarm/loader/assimp_module.h"
#include "swarm/loader/mesh_check.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// Set by swarm/loader/CMakeLists.txt: the module's file name and where this
// build put it.
#ifndef SWARMSIM_ASSIMP_MODULE_NAME
#define SWARMSIM_ASSIMP_MODULE_NAME "libswarmsim_assimp.so"
#endif
#ifndef SWARMSIM_ASSIMP_MODULE_PATH
#define SWARMSIM_ASSIMP_MODULE_PATH ""
#endif

// The module, once per process: a failure is kept and thrown again.
const AssimpModule& Assimp() {
  static const LazyOwnLibrary library(
      OwnLibrary{SWARMSIM_ASSIMP_MODULE_NAME, SWARMSIM_ASSIMP_MODULE_PATH, kAssimpModuleVariable,
                 kAssimpModuleEntry, kAssimpModuleVersion,
                 "mesh files need swarmsim's assimp module (" SWARMSIM_ASSIMP_MODULE_NAME
                 ", on assimp 5.2: Debian's libassimp5, which tools/setup.sh installs)"});
  return *static_cast<const AssimpModule*>(library.Get());
}

// Reads the file's triangles (the assimp module), merging vertices at equal
// positions (STL repeats each corner per facet) so that closed meshes are
// seen closed. `stop_requested` is asked now and then (StopCheck).
std::shared_ptr<const MeshCache::Welded> ReadMeshFile(
    const fs::path& path, const std::string& where, const std::string& text,
    const std::function<bool()>& stop_requested,
    const std::function<void(const std::string&)>& note);

// A stop request during a mesh file's read: the check's own error (the
// program's "interrupted by SIGTERM while the world was loading") once it
// threw, naming the file.
class StopCheck {
 public:
  StopCheck(const std::function<void()>& check_stop, const std::string& text)
      : check_stop_(check_stop), text_(text) {}
  // Does the check throw? (Noted: ThrowIfRequested throws it again.)
  bool Requested() {
    if (!check_stop_ || !error_.empty()) return !error_.empty();
    try {
      check_stop_();
    } catch (const Error& e) {
      error_ = e.what();
    }
    return !error_.empty();
  }
  // Throws the check's error, if it threw (now or before).
  void ThrowIfRequested() {
    if (Requested()) throw Error(error_ + ", reading mesh file '" + text_ + "'");
  }

 private:
  const std::function<void()>& check_stop_;
  const std::string& text_;
  std::string error_;
};

}  // namespace

std::shared_ptr<const TriangleMesh> MeshCache::Get(const fs::path& path, const Vec3& scale,
                                                   const std::string& where,
                                                   const std::string& text) {
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (ec) key = fs::absolute(path, ec).lexically_normal();
  const std::array<double, 3> s{scale.x, scale.y, scale.z};
  if (auto it = meshes_.find({key, s}); it != meshes_.end()) return it->second;
  StopCheck stop(check_stop_, text);
  auto file = files_.find(key);
  if (file == files_.end()) {
    const std::function<bool()> stop_requested = [&stop] { return stop.Requested(); };
    stop.ThrowIfRequested();
    std::shared_ptr<const Welded> welded = ReadMeshFile(path, where, text, stop_requested, note_);
    stop.ThrowIfRequested();  // the read was abandoned, or ended as the signal came
    file = files_.emplace(key, std::move(welded)).first;
  }
  std::vector<Vec3> vertices = file->second->vertices;
  for (Vec3& v : vertices) {
    v = {v.x * scale.x, v.y * scale.y, v.z * scale.z};
    if (!WithinWorld(v)) {
      char text_v[128];
      std::snprintf(text_v, sizeof text_v, "(%g, %g, %g) m; coordinates are at most %g m", v.x, v.y,
                    v.z, kMaxCoordinate);
      throw Error((where.empty() ? "" : where + ": ") + "mesh file '" + text + "' has a vertex " +
                  (scale.x == 1 && scale.y == 1 && scale.z == 1 ? "" : "scaled ") + "at " + text_v);
    }
  }
  // A mirror (an odd count of negative factors, a URDF's scale="1 -1 1")
  // turns the triangles inside out: their winding is reversed.
  std::vector<MeshTriangle> triangles = file->second->triangles;
  if (scale.x * scale.y * scale.z < 0)
    for (MeshTriangle& t : triangles) std::swap(t.v[1], t.v[2]);
  // Building a large one takes seconds: the check abandons it.
  struct Stopped {};
  const std::function<void()> check = [&stop] {
    if (stop.Requested()) throw Stopped{};
  };
  std::shared_ptr<const TriangleMesh> mesh;
  try {
    mesh = std::make_shared<const TriangleMesh>(DisplayPath(path), std::move(vertices),
                                                std::move(triangles), file->second->colors, check);
  } catch (const Stopped&) {
    stop.ThrowIfRequested();
  } catch (const Error& e) {
    throw Error((where.empty() ? "" : where + ": ") + e.what());
  }
  meshes_.emplace(std::make_pair(key, s), mesh);
  return mesh;
}

namespace {

std::shared_ptr<const MeshCache::Welded> ReadMeshFile(
    const fs::path& path, const std::string& where, const std::string& text,
    const std::function<bool()>& stop_requested,
    const std::function<void(const std::string&)>& note) {
  const std::string prefix = where.empty() ? "" : where + ": ";
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".stl" && ext != ".obj" && ext != ".dae")
    throw Error(prefix + "mesh file '" + text +
                "' must be STL, OBJ or COLLADA (a .stl, .obj or .dae name)");
  const std::string bytes = ReadFileOrThrow(path, "mesh file", where, text);
  if (bytes.empty()) throw Error(prefix + "mesh file '" + text + "' is empty");
  if (note && bytes.size() >= MeshCache::kNoteMeshBytes)
    note("reading mesh file '" + text + "' (" + std::to_string(bytes.size() >> 20) + " MiB)");
  // What assimp reads: the bytes, checked (mesh_check.h); of a COLLADA
  // file, the parts the loader uses.
  std::string checked;
  try {
    const std::string name = DisplayPath(path);
    if (ext == ".stl") CheckStlBytes(bytes, name);
    if (ext == ".obj") CheckObjBytes(bytes, name);
    if (ext == ".dae") checked = CheckColladaBytes(bytes, name);
  } catch (const Error& e) {
    throw Error(prefix + e.what());
  }
  const std::string& read = ext == ".dae" ? checked : bytes;

  const AssimpModule* assimp = nullptr;
  try {
    assimp = &Assimp();
  } catch (const Error& e) {
    throw Error(prefix + e.what());
  }
  auto out = std::make_shared<MeshCache::Welded>();
  std::string error = assimp->read_mesh(path.string(), read, text, stop_requested, out.get());
  if (stop_requested()) return out;  // abandoned: the caller throws
  if (!error.empty()) throw Error(prefix + error);
  if (out->triangles.empty()) throw Error(prefix + "mesh file '" + text + "' has no triangles");
  return out;
}

}  // namespace

}  // namespace swarmsim::loader
