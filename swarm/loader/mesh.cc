#include "swarm/loader/mesh.h"

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>

#include "framework/error.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// Reads the file's triangles (assimp), merging vertices at equal positions
// (STL repeats each corner per facet) so that closed meshes are seen closed.
std::shared_ptr<const MeshCache::Welded> ReadMeshFile(const fs::path& path,
                                                      const std::string& where,
                                                      const std::string& text);

}  // namespace

std::shared_ptr<const TriangleMesh> MeshCache::Get(const fs::path& path, const Vec3& scale,
                                                   const std::string& where,
                                                   const std::string& text) {
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (ec) key = fs::absolute(path, ec).lexically_normal();
  const std::array<double, 3> s{scale.x, scale.y, scale.z};
  if (auto it = meshes_.find({key, s}); it != meshes_.end()) return it->second;
  auto file = files_.find(key);
  if (file == files_.end()) file = files_.emplace(key, ReadMeshFile(path, where, text)).first;
  std::vector<Vec3> vertices = file->second->vertices;
  for (Vec3& v : vertices) v = {v.x * scale.x, v.y * scale.y, v.z * scale.z};
  std::shared_ptr<const TriangleMesh> mesh;
  try {
    mesh = std::make_shared<const TriangleMesh>(DisplayPath(path), std::move(vertices),
                                                file->second->triangles, file->second->colors);
  } catch (const Error& e) {
    throw Error((where.empty() ? "" : where + ": ") + e.what());
  }
  meshes_.emplace(std::make_pair(key, s), mesh);
  return mesh;
}

namespace {

std::shared_ptr<const MeshCache::Welded> ReadMeshFile(const fs::path& path,
                                                      const std::string& where,
                                                      const std::string& text) {
  const std::string prefix = where.empty() ? "" : where + ": ";
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".stl" && ext != ".obj" && ext != ".dae")
    throw Error(prefix + "mesh file '" + text +
                "' must be STL, OBJ or COLLADA (a .stl, .obj or .dae name)");
  const std::string bytes = ReadFileOrThrow(path, "mesh file", where, text);
  if (bytes.empty()) throw Error(prefix + "mesh file '" + text + "' is empty");

  Assimp::Importer importer;
  // COLLADA: the file's <unit> applies, its up axis does not (assimp would
  // turn a Z_UP file to Y-up): coordinates stay in the file's own frame,
  // which is what URDF and the world files mean. Node transforms are baked
  // into the vertices (aiProcess_PreTransformVertices).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  // An OBJ or DAE file is read from its folder, so that its material library
  // (mtllib x.mtl beside it) gives the colours; an STL file has none.
  const aiScene* scene = ext != ".stl" ? importer.ReadFile(path.string(), flags)
                                       : importer.ReadFileFromMemory(bytes.data(), bytes.size(),
                                                                     flags, ext.c_str() + 1);
  if (!scene)
    throw Error(prefix + "cannot read mesh file '" + text + "': " + importer.GetErrorString());

  auto out = std::make_shared<MeshCache::Welded>();
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
        auto [it, added] = index_of.emplace(p, static_cast<uint32_t>(out->vertices.size()));
        if (added) out->vertices.push_back({p[0], p[1], p[2]});
        tri.v[k] = it->second;
      }
      if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[0] == tri.v[2]) continue;
      out->triangles.push_back(tri);
      if (any_color) out->colors.push_back(part_color[m]);
    }
  }
  if (out->triangles.empty()) throw Error(prefix + "mesh file '" + text + "' has no triangles");
  return out;
}

}  // namespace

}  // namespace swarmsim::loader
