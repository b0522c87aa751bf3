// The loader's side of framework/object_type.h's ObjectReader: an object
// type's `read` hook reads its keys from one model-file entry through the
// loader's ValueReader (parameters, expressions, file:line:column messages).
#pragma once

#include "framework/object_type.h"
#include "swarm/loader/mesh.h"
#include "swarm/loader/values.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader {

class FieldsObjectReader final : public ObjectReader {
 public:
  // `meshes` may be null (a cache of this reader's own); `registry` too.
  FieldsObjectReader(const ValueReader& values, const Fields& fields, MeshCache* meshes,
                     const ModuleRegistry* registry)
      : values_(values), fields_(fields), meshes_(meshes), registry_(registry) {}

  bool Has(std::string_view key) const override { return fields_.Has(key); }
  double Number(std::string_view key, const NumberRule& rule, bool required) const override {
    return values_.Number(Get(key, required), rule);
  }
  int64_t Integer(std::string_view key, int64_t min, int64_t max) const override {
    return values_.Integer(fields_.Get(key), min, max);
  }
  bool Bool(std::string_view key) const override { return values_.Bool(fields_.Get(key)); }
  std::string String(std::string_view key, bool required) const override {
    return values_.String(Get(key, required));
  }
  std::string Choice(std::string_view key, const std::vector<std::string>& choices,
                     bool required) const override {
    return values_.Choice(Get(key, required), choices);
  }
  std::vector<double> Numbers(std::string_view key, size_t min_count, size_t max_count,
                              const NumberRule& rule) const override {
    return values_.Numbers(fields_.Get(key), min_count, max_count, rule);
  }
  Vec3 Vector3(std::string_view key, const NumberRule& rule, bool required) const override {
    return values_.Vector3(Get(key, required), rule);
  }
  std::vector<Vec3> Vector3List(std::string_view key, size_t min_count, const NumberRule& rule,
                                bool required) const override;
  [[noreturn]] void FailAtElement(std::string_view key, size_t index,
                                  const std::string& message) const override;
  std::vector<std::string> Strings(std::string_view key, size_t max_count,
                                   bool required) const override;
  std::string Where(std::string_view key) const override {
    return values_.file().Where(fields_.Get(key).mark);
  }
  [[noreturn]] void Fail(std::string_view key, const std::string& message) const override {
    values_.Fail(fields_.Get(key), message);
  }
  [[noreturn]] void FailAtKey(std::string_view key, const std::string& message) const override {
    values_.file().Fail(fields_.Get(key).key_mark, message);
  }
  std::shared_ptr<const TriangleMesh> Mesh(std::string_view key, const Vec3& scale) const override;
  const ModuleRegistry* registry() const override { return registry_; }
  std::vector<std::unique_ptr<ObjectReader>> Items(std::string_view key) const override;
  void Expect(std::span<const std::string> known) const override { fields_.Expect(known); }
  void Require(std::string_view key) const override {
    if (!single_value_) fields_.Require(key);
  }
  std::unique_ptr<ObjectReader> Map(std::string_view key, const std::string& what,
                                    std::string_view expected) const override;
  std::vector<std::unique_ptr<ObjectReader>> Elements(std::string_view key,
                                                      std::string_view list_what,
                                                      const std::string& what,
                                                      std::string_view scalar_key) const override;
  [[noreturn]] void FailHere(const std::string& message) const override {
    values_.file().Fail(fields_.mark(), message);
  }
  std::vector<std::unique_ptr<ObjectReader>> Maps(std::string_view key, std::string_view list_what,
                                                  const std::string& what) const override;
  bool IsList(std::string_view key) const override {
    return !single_value_ && fields_.Get(key).node.IsSequence();
  }
  std::vector<std::string> Keys() const override { return fields_.keys(); }
  std::string WhereKey(std::string_view key) const override {
    return values_.file().Where(fields_.Get(key).key_mark);
  }
  std::string WhereHere() const override { return values_.file().Where(fields_.mark()); }

 private:
  // An item's reader owns its map's fields; `single_value`: a bare value
  // read as a map of one key (Elements), whose value is there as it is.
  FieldsObjectReader(const ValueReader& values, std::unique_ptr<Fields> fields, MeshCache* meshes,
                     const ModuleRegistry* registry, bool single_value = false)
      : values_(values),
        fields_(*fields),
        meshes_(meshes),
        registry_(registry),
        owned_fields_(std::move(fields)),
        single_value_(single_value) {}

  // A single value's one key is never "required": an empty value is read
  // (and refused) as a value.
  Field Get(std::string_view key, bool required) const {
    return required && !single_value_ ? fields_.Require(key) : fields_.Get(key);
  }

  const ValueReader& values_;
  const Fields& fields_;
  MeshCache* meshes_;
  const ModuleRegistry* registry_;
  std::unique_ptr<Fields> owned_fields_;
  bool single_value_ = false;
};

}  // namespace swarmsim::loader
