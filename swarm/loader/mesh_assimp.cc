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
#include <cmath>
#include <exception>
#include <filesystem>
#include <map>
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

// Reads the triangles of `path` (`bytes` its checked contents), merging
// vertices at equal positions (STL repeats each corner per facet) so that
// closed meshes are seen closed. "" or what went wrong.
std::string ReadWithAssimp(const std::string& path, const std::string& bytes,
                           const std::string& text, MeshCache::Welded* out) try {
  Assimp::Importer importer;
  importer.SetIOHandler(new CheckedFiles(path, &bytes));  // the importer owns it
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
  if (!scene) return "cannot read mesh file '" + text + "': " + importer.GetErrorString();
  size_t faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) faces += scene->mMeshes[m]->mNumFaces;
  if (faces > static_cast<size_t>(kMaxMeshTriangles))
    return "mesh file '" + text + "' has " + std::to_string(faces) +
           " faces; the limit for a mesh file is " + std::to_string(kMaxMeshTriangles) +
           " triangles";

  std::map<std::array<double, 3>, uint32_t> index_of;
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
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      MeshTriangle tri{};
      for (int k = 0; k < 3; ++k) {
        const aiVector3D& v = mesh->mVertices[face.mIndices[k]];
        const std::array<double, 3> p{v.x, v.y, v.z};
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
          return "mesh file '" + text +
                 "' has a vertex that is not finite (after its unit and node transforms)";
        auto [it, added] = index_of.emplace(p, static_cast<uint32_t>(out->vertices.size()));
        if (added) out->vertices.push_back({p[0], p[1], p[2]});
        tri.v[k] = it->second;
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
