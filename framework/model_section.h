// Model-file sections that modules own: a top-level key of a model file
// (`ik_groups:`) that a module reads itself, with the model's parameter
// values, and applies to each copy built from the model, declared in the
// ModuleRegistry as a world-file section is (world_section.h). The loader
// knows its own model keys (model, description, parameters, objects); every
// other key is a registered section's, so the loader names no module and an
// unknown key still lists them all. A `models:` entry of a world file may
// hold the same key (an imported robot's IK groups), read with the world's
// values and applied to the entry's copies too.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "framework/handle.h"
#include "framework/object_type.h"

namespace swarmsim {

class World;

// What a section read from one model file (or one models entry): the
// module's own type, kept by the loader until the copies are built.
class ModelSectionData {
 public:
  virtual ~ModelSectionData() = default;
  // For `swarmsim describe`: "ik (2 IK groups)"; empty: nothing to say.
  virtual std::string Describe() const { return {}; }
};

// A copy of a model, built from the model's own description (the entry's
// first copy, and each copy with values of its own; the others are
// duplicated from the first, and a module follows them as a SceneListener).
struct ModelCopy {
  ObjectId root;
  const std::string& model;      // the model's name: "arm"
  const std::string& root_name;  // the root's name in the file (a URDF's root link)
  // Every object's path in the model from its root ("leg1/footTip"), in
  // tree order: what a path may name, for suggestions.
  std::span<const std::string> paths;
};

struct ModelSectionDescriptor {
  std::string key;  // the model file's key: "ik_groups"
  std::string doc;  // one line (worlds/README.md documents the key)
  // Reads the section from `top`, the model file's top level (or a models
  // entry's mapping), its values resolved with the model's parameters (a
  // copy with values of its own reads it again with them): the section
  // reads its own key (ObjectReader::Maps, Map, Elements) and gives null
  // when it is absent. `model` is the model's name, for messages. Errors
  // name file:line:column through `top`; what a copy resolves later (a
  // path in the model) keeps its place (ObjectReader::Where).
  std::shared_ptr<const ModelSectionData> (*read)(const ObjectReader& top,
                                                  const std::string& model) = nullptr;
  // Applies what `read` gave to a copy just built (its objects exist, its
  // model instance too). Throws swarmsim::Error with the file:line:column
  // `read` kept.
  void (*apply)(const ModelSectionData& data, const ModelCopy& copy, World* world) = nullptr;
};

}  // namespace swarmsim
