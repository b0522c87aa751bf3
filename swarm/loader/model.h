// Model files (worlds/models/*.yaml): a named tree of objects with declared
// parameters. A model is read once, resolved per `models:` entry of the
// world (its values may use that entry's parameters), built into the scene
// once and then duplicated for the other copies.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "swarm/loader/mesh.h"
#include "swarm/loader/values.h"
#include "swarm/loader/yaml.h"

namespace swarmsim {
class ModuleRegistry;
}  // namespace swarmsim

namespace swarmsim::loader {

// One object with its values resolved, and its children.
struct ObjectSpec {
  std::string name;
  ObjectType type = ObjectType::kDummy;
  Pose X_PO;  // pose in the parent
  // The object's row (of its type's row type, object_type.h) in a table of
  // its own; null for a type without rows.
  std::shared_ptr<RowTable> row;
  // The row as `Row` if the object is of `type`, else null (the placement
  // footprint reads shapes and joints).
  template <typename Row>
  const Row* As(ObjectType want) const {
    return type == want && row ? static_cast<const Row*>(row->At(0)) : nullptr;
  }
  // A shape's settings (its row is a Shared<ShapeData>), else null.
  const ShapeData* AsShape() const {
    const auto* shape = As<Shared<ShapeData>>(ObjectType::kShape);
    return shape != nullptr ? &**shape : nullptr;
  }
  std::shared_ptr<const ScriptSource> script;
  bool script_explicit = false;  // script: {file: ..., explicit: true}
  std::vector<ObjectSpec> children;
};

// Script files read so far: one ScriptSource per file, shared by every
// object (and every copy) that uses it.
class ScriptCache {
 public:
  // `text` is the path as written in the file, `where` its position.
  std::shared_ptr<const ScriptSource> Get(const std::filesystem::path& path,
                                          const std::string& where, const std::string& text);

 private:
  std::map<std::filesystem::path, std::shared_ptr<const ScriptSource>> sources_;
};

struct ModelParameterDecl {
  std::string name;
  Field default_value;
  std::string unit;
  std::string description;
  YAML::Mark mark;
  // range: [min, max] (numbers only): every value given is checked.
  bool has_range = false;
  double min = 0, max = 0;
};

// A model file, checked but not resolved.
struct ModelFile {
  YamlFile file;
  std::string name;  // "footbot"
  std::vector<ModelParameterDecl> parameters;
  Field root;  // the root object
  // The file's top-level mapping: registered model-file sections
  // (framework/model_section.h: `ik_groups`) read their keys from it.
  Field top;
  // A model imported from another format (a URDF file, swarm/loader/urdf.h):
  // its objects, built once; `file` is then the world file naming it (the
  // entry's keys are read there) and `root` is not present.
  std::shared_ptr<const ObjectSpec> imported;
  std::string imported_file;                // the imported file, as the world names it
  std::vector<std::string> import_summary;  // `swarmsim describe` lines
  // An imported model's joints that are no joint objects, by name -> kind
  // ("fixed"): named when a world gives one of them a position.
  std::map<std::string, std::string> merged_joints;
};

// `used_by` (file:line:column of the reference) is named when the file is
// not a model at all. `section_keys`: the registered model-file sections'
// keys (framework/model_section.h), accepted beside the loader's own.
ModelFile ReadModelFile(YamlFile file, const std::string& used_by,
                        std::span<const std::string> section_keys = {});

// The world file's `objects:`: objects of the scene that belong to no model
// (collections, distance objects, markers), each an entry as in a model file.
std::vector<ObjectSpec> ReadSceneObjects(const YamlFile& file, const Field& list,
                                         const ValueReader& values, ScriptCache* scripts,
                                         MeshCache* meshes, const ModuleRegistry* registry);

// Valid parameter name: a Lua identifier that is not a keyword.
bool IsParameterName(std::string_view name);

// The root object of `model`, values resolved by `values` (whose scope holds
// the world's and this entry's model parameters). Scripts resolve against
// the model file's folder, and so do mesh files (read once through `meshes`;
// null: a cache of this call's own). Plugin sensor types are looked up in
// `registry` (null: there are none).
ObjectSpec ResolveModel(const ModelFile& model, const ValueReader& values, ScriptCache* scripts,
                        MeshCache* meshes = nullptr, const ModuleRegistry* registry = nullptr);

// Shape keys and object poses, shared with the world's obstacles (the shape
// type's own reader, framework/types/shape_type.cc). A mesh's file is
// relative to the file being read; `meshes` null: no sharing.
ShapeData ReadShape(const ValueReader& values, const Fields& fields, MeshCache* meshes = nullptr);
Pose ReadPose(const ValueReader& values, const Fields& fields);
// orientation_deg: [roll, pitch, yaw] or heading_deg (identity if neither).
Quat ReadOrientation(const ValueReader& values, const Fields& fields);
// Keys of ReadShape and ReadPose.
const std::vector<std::string>& ShapeKeys();
const std::vector<std::string>& PoseKeys();

// Adds `spec` and its subtree to `scene` under `parent`; returns its id.
ObjectId AddToScene(const ObjectSpec& spec, ObjectId parent, Scene* scene);

// The plane footprint of a model in the model's frame (where a copy is
// placed; the root sits at its own position and orientation in it, usually
// the identity): every shape lies within `radius` of the frame's z axis;
// `bottom` is the lowest z of any shape (a copy stands on the ground at
// z = -bottom).
struct Footprint {
  double radius = 0;
  double bottom = 0;
  double top =
      0;  // the highest z of any shape (placement keeps copies clear of map voxels below it)
};
Footprint ComputeFootprint(const ObjectSpec& root);

}  // namespace swarmsim::loader
