// One model-file entry written in C++ for the tests of the modules' object
// types: an ObjectReader over numbers, strings and lists of points, whose
// errors throw swarmsim::Error naming "entry.KEY" where the loader's name
// file:line:column (the loader's side is tested in tests/swarm/loader).
// A type's `read` hook runs on it as the loader runs it:
//   EntryReader entry;
//   entry.numbers["range"] = {2};
//   ReadRow(scene, type, entry, &row);
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/suggest.h"

namespace swarmsim::testing {

class EntryReader final : public ObjectReader {
 public:
  std::map<std::string, std::vector<double>> numbers;       // a number, a bool (0/1) or a list
  std::map<std::string, std::vector<std::string>> strings;  // a string or a list of them
  std::map<std::string, std::vector<Vec3>> points;          // a list of [x, y, z]

  bool Has(std::string_view key) const override {
    const std::string k(key);
    return numbers.count(k) || strings.count(k) || points.count(k);
  }
  double Number(std::string_view key, const NumberRule& rule, bool required) const override {
    if (!Has(key)) {
      if (required) FailAtKey(key, "is required");
      return 0;
    }
    return Check(key, Get(key).at(0), rule);
  }
  int64_t Integer(std::string_view key, int64_t min, int64_t max) const override {
    const double v = Get(key).at(0);
    if (v < static_cast<double>(min) || v > static_cast<double>(max) || v != std::floor(v))
      Fail(key, "must be an integer from " + std::to_string(min) + " to " + std::to_string(max));
    return static_cast<int64_t>(v);
  }
  bool Bool(std::string_view key) const override { return Get(key).at(0) != 0; }
  std::string String(std::string_view key, bool required) const override {
    auto it = strings.find(std::string(key));
    if (it == strings.end()) {
      if (required) FailAtKey(key, "is required");
      return "";
    }
    return it->second.at(0);
  }
  std::string Choice(std::string_view key, const std::vector<std::string>& choices,
                     bool required) const override {
    const std::string value = String(key, required);
    if (std::find(choices.begin(), choices.end(), value) == choices.end())
      Fail(key, "unknown '" + value + "'" + Suggest(value, choices));
    return value;
  }
  std::vector<double> Numbers(std::string_view key, size_t min_count, size_t max_count,
                              const NumberRule& rule) const override {
    const std::vector<double>& v = Get(key);
    if (v.size() < min_count || v.size() > max_count)
      Fail(key,
           "needs " + std::to_string(min_count) + " to " + std::to_string(max_count) + " numbers");
    for (double x : v) Check(key, x, rule);
    return v;
  }
  Vec3 Vector3(std::string_view key, const NumberRule& rule, bool required) const override {
    if (!Has(key)) {
      if (required) FailAtKey(key, "is required");
      return {};
    }
    const std::vector<double> v = Numbers(key, 3, 3, rule);
    return {v[0], v[1], v[2]};
  }
  std::vector<Vec3> Vector3List(std::string_view key, size_t min_count, const NumberRule& rule,
                                bool required) const override {
    auto it = points.find(std::string(key));
    if (it == points.end()) {
      if (required) FailAtKey(key, "is required");
      return {};
    }
    if (it->second.size() < min_count)
      Fail(key, "needs at least " + std::to_string(min_count) + " points");
    for (const Vec3& p : it->second) {
      Check(key, p.x, rule);
      Check(key, p.y, rule);
      Check(key, p.z, rule);
    }
    return it->second;
  }
  [[noreturn]] void FailAtElement(std::string_view key, size_t index,
                                  const std::string& message) const override {
    throw Error(Where(key) + "[" + std::to_string(index) + "]: " + message);
  }
  std::vector<std::string> Strings(std::string_view key, size_t max_count,
                                   bool required) const override {
    auto it = strings.find(std::string(key));
    if (it == strings.end()) {
      if (required) FailAtKey(key, "is required");
      return {};
    }
    if (it->second.size() > max_count) Fail(key, "too many names");
    return it->second;
  }
  std::string Where(std::string_view key) const override { return "entry." + std::string(key); }
  [[noreturn]] void Fail(std::string_view key, const std::string& message) const override {
    throw Error(Where(key) + ": " + message);
  }
  [[noreturn]] void FailAtKey(std::string_view key, const std::string& message) const override {
    Fail(key, message);
  }
  std::shared_ptr<const TriangleMesh> Mesh(std::string_view, const Vec3&) const override {
    return nullptr;
  }
  const ModuleRegistry* registry() const override { return nullptr; }
  std::vector<std::unique_ptr<ObjectReader>> Items(std::string_view) const override { return {}; }
  void Expect(std::span<const std::string>) const override {}

 private:
  const std::vector<double>& Get(std::string_view key) const {
    auto it = numbers.find(std::string(key));
    if (it == numbers.end()) FailAtKey(key, "is required");
    return it->second;
  }
  double Check(std::string_view key, double v, const NumberRule& rule) const {
    if (!std::isfinite(v) || v < rule.min || v > rule.max || (rule.min_exclusive && v == rule.min))
      Fail(key, "must be " + std::string(rule.text));
    return v;
  }
};

// The type named `type_name` of `scene` (registered by a module).
inline ObjectType TypeNamed(const Scene& scene, std::string_view type_name) {
  ObjectType type{};
  if (!scene.FindType(type_name, &type)) throw Error("no type " + std::string(type_name));
  return type;
}

// Runs the `read` hook of the type named `type_name` on `entry` into `row`
// (a default row of that type), as the loader does.
template <typename Row>
void ReadRow(const Scene& scene, std::string_view type_name, const ObjectReader& entry, Row* row) {
  const ObjectTypeDescriptor& type = scene.type_descriptor(TypeNamed(scene, type_name));
  type.read(type, entry, row);
}

// The row of the object `id` of the type named `type_name`.
template <typename Row>
Row& RowOf(Scene* scene, std::string_view type_name, ObjectId id) {
  auto& rows = scene->rows<Row>(TypeNamed(*scene, type_name));
  return rows.rows[scene->row_at(scene->SlotOf(id))];
}

}  // namespace swarmsim::testing
