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

std::vector<Vec3> FieldsObjectReader::Vector3List(std::string_view key, size_t min_count,
                                                  const NumberRule& rule, bool required) const {
  const Field field = Get(key, required);
  std::vector<Vec3> out;
  if (!field.present()) return out;
  const std::vector<Field> elements = ListElements(values_.file(), field, "[x, y, z] lists");
  if (elements.size() < min_count)
    values_.Fail(field, "'" + field.name + "' needs at least " + std::to_string(min_count) +
                            " [x, y, z] lists, e.g. [[0, 0, 0], [1, 0, 0]] (got " +
                            std::to_string(elements.size()) + ")");
  for (const Field& element : elements) out.push_back(values_.Vector3(element, rule));
  return out;
}

void FieldsObjectReader::FailAtElement(std::string_view key, size_t index,
                                       const std::string& message) const {
  const Field field = fields_.Get(key);
  const std::vector<Field> elements = ListElements(values_.file(), field, "elements");
  values_.Fail(index < elements.size() ? elements[index] : field, message);
}

std::vector<std::string> FieldsObjectReader::Strings(std::string_view key, size_t max_count,
                                                     bool required) const {
  const Field field = Get(key, required);
  std::vector<std::string> out;
  if (!field.present()) return out;
  if (field.node.IsScalar()) {
    out.push_back(values_.String(field));
    return out;
  }
  const std::vector<Field> elements = ListElements(values_.file(), field, "names");
  if (elements.size() > max_count)
    values_.Fail(field, "'" + field.name + "' takes at most " + std::to_string(max_count) +
                            " names (got " + std::to_string(elements.size()) + ")");
  for (const Field& element : elements) out.push_back(values_.String(element));
  return out;
}

std::vector<std::unique_ptr<ObjectReader>> FieldsObjectReader::Items(std::string_view key) const {
  std::vector<std::unique_ptr<ObjectReader>> out;
  for (const Field& item : ListElements(values_.file(), fields_.Get(key), "maps")) {
    auto fields =
        std::make_unique<Fields>(values_.file(), item, item.name + " of " + fields_.what());
    out.push_back(std::unique_ptr<ObjectReader>(
        new FieldsObjectReader(values_, std::move(fields), meshes_, registry_)));
  }
  return out;
}

}  // namespace swarmsim::loader

namespace swarmsim::loader {

std::unique_ptr<ObjectReader> FieldsObjectReader::Map(std::string_view key, const std::string& what,
                                                      std::string_view expected) const {
  const Field field = fields_.Get(key);
  if (!field.present()) return nullptr;
  if (!field.node.IsMap())
    values_.file().Fail(field.mark, "'" + std::string(key) + "' must be " + std::string(expected) +
                                        " (got " + Describe(field.node) + ")");
  auto fields = std::make_unique<Fields>(values_.file(), field, what);
  return std::unique_ptr<ObjectReader>(
      new FieldsObjectReader(values_, std::move(fields), meshes_, registry_));
}

std::vector<std::unique_ptr<ObjectReader>> FieldsObjectReader::Elements(
    std::string_view key, std::string_view list_what, const std::string& what,
    std::string_view scalar_key) const {
  std::vector<std::unique_ptr<ObjectReader>> out;
  for (Field& element : ListElements(values_.file(), fields_.Get(key), list_what)) {
    const bool is_map = element.node.IsMap();
    std::unique_ptr<Fields> fields;
    if (is_map) {
      fields = std::make_unique<Fields>(values_.file(), element, what);
    } else {
      element.name = std::string(scalar_key);
      fields = std::make_unique<Fields>(Fields::Single(values_.file(), element, what));
    }
    out.push_back(std::unique_ptr<ObjectReader>(
        new FieldsObjectReader(values_, std::move(fields), meshes_, registry_, !is_map)));
  }
  return out;
}

}  // namespace swarmsim::loader

namespace swarmsim::loader {

std::vector<std::unique_ptr<ObjectReader>> FieldsObjectReader::Maps(std::string_view key,
                                                                    std::string_view list_what,
                                                                    const std::string& what) const {
  std::vector<std::unique_ptr<ObjectReader>> out;
  for (const Field& element : ListElements(values_.file(), fields_.Get(key), list_what)) {
    auto fields = std::make_unique<Fields>(values_.file(), element, what);
    out.push_back(std::unique_ptr<ObjectReader>(
        new FieldsObjectReader(values_, std::move(fields), meshes_, registry_)));
  }
  return out;
}

}  // namespace swarmsim::loader
