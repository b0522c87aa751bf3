#include "swarm/loader/object_reader.h"

namespace swarmsim::loader {

std::shared_ptr<const TriangleMesh> FieldsObjectReader::Mesh(std::string_view key,
                                                             const Vec3& scale) const {
  const Field file = fields_.Require(key);
  const std::string text = values_.String(file);
  if (text.empty())
    values_.Fail(file, "'" + file.name + "' must be a mesh file name (.stl or .obj)");
  MeshCache local;
  MeshCache* meshes = meshes_ != nullptr ? meshes_ : &local;
  return meshes->Get(values_.file().path().parent_path() / text, scale,
                     values_.file().Where(file.mark), text);
}

}  // namespace swarmsim::loader
