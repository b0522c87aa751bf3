// Mesh files read with assimp, inside the assimp module (assimp_module.h):
// the importer behind MeshCache (mesh.h), given bytes mesh.cc has read and
// checked (mesh_check.h).
#include <assimp/DefaultIOSystem.h>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <assimp/ProgressHandler.hpp>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "swarm/loader/assimp_module.h"

// assimp's assertions: Debian's assimp 5.2 is built with them on, and a
// failed one calls std::abort() (exit 134, no message of ours, no outputs).
// 5.2 has no setAiAssertHandler (5.3 does), but every assertion calls this
// function through the library's PLT, so the program's own definition
// replaces the library's (here the module's: it comes before libassimp in
// the module's own lookup scope): it throws, and assimp's importer catches the
// exception (BaseImporter::ReadFile) and returns no scene with its text,
// which ReadMeshFile reports. mesh_check.h refuses the inputs known to
// fail one first, with the file and line; this is the backstop for the
// rest. (Default visibility: a Python module built with hidden symbols
// still replaces it.)
namespace Assimp {
__attribute__((visibility("default"))) void aiAssertViolation(const char* expression,
                                                              const char* file, int line) {
  throw std::runtime_error(std::string("assimp's check '") + expression + "' failed (" + file +
                           ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// The files assimp opens: the mesh file itself from the bytes already read
// and checked (never read twice), others (an OBJ's material library) only
// if they are regular files of a sane size (not a FIFO, which would block,
// nor a device).
class CheckedFiles : public Assimp::DefaultIOSystem {
 public:
  CheckedFiles(std::string path, const std::string* bytes)
      : path_(std::move(path)), bytes_(bytes) {}
  bool Exists(const char* file) const override { return file == path_ || Readable(file); }
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override {
    if (file == path_)
      return new Assimp::MemoryIOStream(reinterpret_cast<const uint8_t*>(bytes_->data()),
                                        bytes_->size());
    if (!Readable(file) || std::string_view(mode).find_first_of("wa+") != std::string_view::npos)
      return nullptr;
    return DefaultIOSystem::Open(file, mode);
  }

 private:
  static bool Readable(const char* file) {
    constexpr uintmax_t kMaxBytes = 64 << 20;  // as ReadFileOrThrow
    std::error_code ec;
    return fs::is_regular_file(file, ec) && fs::file_size(file, ec) <= kMaxBytes && !ec;
  }
  std::string path_;
  const std::string* bytes_;
};

// assimp's progress reports: false (the import is abandoned) once a stop
// is requested.
class StopCheck : public Assimp::ProgressHandler {
 public:
  explicit StopCheck(const std::function<bool()>& stop_requested)
      : stop_requested_(stop_requested) {}
  bool Update(float) override { return !stop_requested_(); }

 private:
  const std::function<bool()>& stop_requested_;
};

// Vertices at equal positions, each numbered in the order first seen: an
// open-addressing table of indices into `vertices` (a 1.3M-triangle STL
// has 3.9M corners: a std::map of them took 6 s, this a fraction of one).
class VertexWelder {
 public:
  VertexWelder(size_t corners, std::vector<Vec3>* vertices) : vertices_(vertices) {
    size_t capacity = 16;
    while (capacity < 2 * corners) capacity *= 2;
    slots_.assign(capacity, kEmpty);
  }
  // The index of the vertex at p, added if new.
  uint32_t Find(const Vec3& p) {
    const size_t mask = slots_.size() - 1;
    for (size_t i = Hash(p) & mask;; i = (i + 1) & mask) {
      const uint32_t index = slots_[i];
      if (index == kEmpty) {
        slots_[i] = static_cast<uint32_t>(vertices_->size());
        vertices_->push_back(p);
        return slots_[i];
      }
      const Vec3& v = (*vertices_)[index];
      if (v.x == p.x && v.y == p.y && v.z == p.z) return index;  // -0 equals 0
    }
  }

 private:
  static constexpr uint32_t kEmpty = UINT32_MAX;
  static uint64_t Bits(double x) { return std::bit_cast<uint64_t>(x + 0.0); }  // -0 as 0
  static size_t Hash(const Vec3& p) {
    uint64_t h = Bits(p.x) * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 29) ^ Bits(p.y)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 31) ^ Bits(p.z)) * 0x94D049BB133111EBull;
    return static_cast<size_t>(h ^ (h >> 32));
  }
  std::vector<uint32_t> slots_;
  std::vector<Vec3>* vertices_;
};

// Faces between two looks at the stop request while welding.
constexpr unsigned kFacesPerStopCheck = 1 << 16;

// Reads the triangles of `path` (`bytes` its checked contents), merging
// vertices at equal positions (STL repeats each corner per facet) so that
// closed meshes are seen closed. "" or what went wrong; "" with nothing
// read once `stop_requested` said yes (assimp's progress reports and the
// weld ask it now and then).
std::string ReadWithAssimp(const std::string& path, const std::string& bytes,
                           const std::string& text, const std::function<bool()>& stop_requested,
                           MeshCache::Welded* out) try {
  Assimp::Importer importer;
  importer.SetIOHandler(new CheckedFiles(path, &bytes));       // the importer owns it
  importer.SetProgressHandler(new StopCheck(stop_requested));  // and this
  // COLLADA: the file's <unit> applies, its up axis does not (assimp would
  // turn a Z_UP file to Y-up): coordinates stay in the file's own frame,
  // which is what URDF and the world files mean. Node transforms are baked
  // into the vertices (aiProcess_PreTransformVertices).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  // Read by its path, so that an OBJ file's material library (mtllib x.mtl
  // beside it) gives the colours.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path, flags);
  } catch (const std::exception& e) {  // one of assimp's checks failed outside its importer
    return "cannot read mesh file '" + text + "': " + e.what();
  }
  if (stop_requested()) return "";
  if (!scene) return "cannot read mesh file '" + text + "': " + importer.GetErrorString();
  size_t faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) faces += scene->mMeshes[m]->mNumFaces;
  if (faces > static_cast<size_t>(kMaxMeshTriangles))
    return "mesh file '" + text + "' has " + std::to_string(faces) +
           " faces; the limit for a mesh file is " + std::to_string(kMaxMeshTriangles) +
           " triangles";

  VertexWelder welder(3 * faces, &out->vertices);
  // The diffuse colour of each part's material; assimp's stand-in material
  // for a file without any has none.
  bool any_color = false;
  std::vector<Vec3> part_color(scene->mNumMeshes, Vec3{0.7, 0.7, 0.7});
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const unsigned index = scene->mMeshes[m]->mMaterialIndex;
    if (index >= scene->mNumMaterials) continue;
    const aiMaterial* material = scene->mMaterials[index];
    aiString name;
    aiColor4D diffuse;
    if (material->Get(AI_MATKEY_NAME, name) == AI_SUCCESS &&
        std::string(name.C_Str()) == AI_DEFAULT_MATERIAL_NAME)
      continue;
    if (aiGetMaterialColor(material, AI_MATKEY_COLOR_DIFFUSE, &diffuse) != AI_SUCCESS) continue;
    part_color[m] = {std::clamp<double>(diffuse.r, 0, 1), std::clamp<double>(diffuse.g, 0, 1),
                     std::clamp<double>(diffuse.b, 0, 1)};
    any_color = true;
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      if (f % kFacesPerStopCheck == kFacesPerStopCheck - 1 && stop_requested()) return "";
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      MeshTriangle tri{};
      for (int k = 0; k < 3; ++k) {
        const aiVector3D& v = mesh->mVertices[face.mIndices[k]];
        const Vec3 p{v.x, v.y, v.z};
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          return "mesh file '" + text +
                 "' has a vertex that is not finite (after its unit and node transforms)";
        tri.v[k] = welder.Find(p);
      }
      if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[0] == tri.v[2]) continue;
      out->triangles.push_back(tri);
      if (any_color) out->colors.push_back(part_color[m]);
    }
  }
  return "";
} catch (const std::exception& e) {
  return "cannot read mesh file '" + text + "': " + e.what();
}

}  // namespace

}  // namespace swarmsim::loader

// The module's table (assimp_module.h).
extern "C" __attribute__((visibility("default"))) const void* swarmsim_assimp_module() {
  static const swarmsim::loader::AssimpModule module{swarmsim::loader::kAssimpModuleVersion,
                                                     swarmsim::loader::ReadWithAssimp};
  return &module;
}
