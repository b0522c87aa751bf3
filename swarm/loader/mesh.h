// Mesh files (shape: mesh, file: part.stl|.obj|.dae): read with assimp, welded
// into a framework TriangleMesh (plain arrays; assimp stays in mesh.cc),
// once per file and scale per world, and shared by every shape and copy.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/math.h"
#include "framework/mesh.h"

namespace swarmsim::loader {

// Limits on a mesh file, checked before assimp reads it (mesh_check.h). The
// file itself is at most 64 MiB, as every file a world reads.
inline constexpr int64_t kMaxMeshTriangles = 2000000;    // polygons split, each instance counted
inline constexpr int64_t kMaxColladaElements = 1000000;  // XML elements of a COLLADA file
inline constexpr int kMaxColladaNodeDepth = 256;     // nested nodes, instance_node hops included
inline constexpr int64_t kMaxColladaNodes = 100000;  // scene nodes, each instance counted

class MeshCache {
 public:
  // The mesh in `path` (STL, ASCII or binary, OBJ or COLLADA: its unit
  // applies, its up axis does not), each vertex scaled by
  // `scale` (nonzero factors; a mirror, an odd count of negative ones,
  // reverses the triangles' winding so they still face out). Throws swarmsim::Error "<where>: mesh
  // file 'text' ..." for a missing, unreadable, unsupported or empty file, and
  // "<where>: <file>:<line>: ..." for one that breaks a limit above or that
  // assimp would not survive (mesh_check.h); a vertex, once scaled, is
  // finite and within kMaxCoordinate of the file's origin.
  std::shared_ptr<const TriangleMesh> Get(const std::filesystem::path& path, const Vec3& scale,
                                          const std::string& where, const std::string& text);
  // Files read so far (each once, whatever the scales).
  size_t files_read() const { return files_.size(); }
  // `check_stop` is called now and then while a file is read and its mesh
  // built (a large one takes seconds); it may throw swarmsim::Error to
  // abandon the load (LoadOptions::check_stop): Get throws it naming the
  // file. `note` is told when a file of kNoteMeshBytes or more is read.
  void set_load_hooks(std::function<void()> check_stop,
                      std::function<void(const std::string&)> note) {
    check_stop_ = std::move(check_stop);
    note_ = std::move(note);
  }
  static constexpr size_t kNoteMeshBytes = size_t{8} << 20;

  // A file's triangles, vertices at equal positions merged, unscaled.
  struct Welded {
    std::vector<Vec3> vertices;
    std::vector<MeshTriangle> triangles;
    std::vector<Vec3> colors;  // per triangle, the materials' diffuse colours; or empty
  };

 private:
  std::function<void()> check_stop_;
  std::function<void(const std::string&)> note_;
  std::map<std::filesystem::path, std::shared_ptr<const Welded>> files_;
  std::map<std::pair<std::filesystem::path, std::array<double, 3>>,
           std::shared_ptr<const TriangleMesh>>
      meshes_;
};

}  // namespace swarmsim::loader
