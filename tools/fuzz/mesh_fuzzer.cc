// A mesh file through the loader's MeshCache (swarm/loader/mesh.h: assimp,
// welding, the TriangleMesh checks), as a shape's `mesh: part.EXT` reads it.
// Built once per format: SWARMSIM_FUZZ_MESH_EXT is ".stl", ".obj" or ".dae".
// An OBJ file finds fuzz.mtl beside it (materials: colours), a COLLADA file
// nothing.
#include "framework/error.h"
#include "swarm/loader/mesh.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

constexpr char kMaterials[] = R"(# fuzz.mtl: materials an OBJ input may name (mtllib fuzz.mtl).
newmtl red
Kd 1 0 0
newmtl green
Kd 0 1 0
Ka 0.1 0.1 0.1
Ks 0.5 0.5 0.5
d 0.5
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path file = [] {
    const std::filesystem::path dir = fuzz::TempFolder() / "mesh";
    std::filesystem::create_directories(dir);
    fuzz::WriteFile(dir / "fuzz.mtl", kMaterials);
    return dir / ("fuzz" SWARMSIM_FUZZ_MESH_EXT);
  }();
  fuzz::WriteFile(file, data, size);
  try {
    loader::MeshCache meshes;
    meshes.Get(file, Vec3{1, 1, 1}, "fuzz.yaml:1:1", file.filename().string());
    meshes.Get(file, Vec3{0.5, 2, 1}, "fuzz.yaml:1:1", file.filename().string());
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  return 0;
}
