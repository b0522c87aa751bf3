// An ObjectReader over a few keys given in the test, for the types' `read`
// hooks (framework/object_type.h) without the loader or YAML: each key's
// value is a number, a bool, a string or a list of numbers or strings; its
// "file:line:column" is "model.yaml:<n>:3", n its position among the keys
// (from 2: line 1 is the object's name). Errors are thrown as the loader's
// are: swarmsim::Error("model.yaml:<n>:<col>: message"). Number bounds
// (NumberRule) are checked as the loader checks them.
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"

namespace swarmsim::testing {

class FakeReader : public ObjectReader {
 public:
  using Value =
      std::variant<double, bool, std::string, std::vector<double>, std::vector<std::string>>;

  FakeReader() = default;
  FakeReader(std::initializer_list<std::pair<const std::string, Value>> keys) {
    for (const auto& [key, value] : keys) Set(key, value);
  }
  void Set(const std::string& key, Value value) {
    if (!values_.count(key)) lines_[key] = static_cast<int>(lines_.size()) + 2;
    values_[key] = std::move(value);
  }

  bool Has(std::string_view key) const override { return values_.count(std::string(key)) != 0; }
  double Number(std::string_view key, const NumberRule& rule, bool required) const override {
    if (!Present(key, required)) return 0;
    const double* v = std::get_if<double>(&At(key));
    if (v == nullptr) Raise(key, Must(key, rule.text), 3);
    CheckNumber(key, *v, rule);
    return *v;
  }
  int64_t Integer(std::string_view key, int64_t min, int64_t max) const override {
    const double v = Number(key, kAnyNumber, true);
    if (v != std::floor(v) || v < static_cast<double>(min) || v > static_cast<double>(max))
      Raise(key, Must(key, "a whole number in range"), 3);
    return static_cast<int64_t>(v);
  }
  bool Bool(std::string_view key) const override {
    const bool* v = std::get_if<bool>(&At(key));
    if (v == nullptr) Raise(key, Must(key, "true or false"), 3);
    return *v;
  }
  std::string String(std::string_view key, bool required) const override {
    if (!Present(key, required)) return "";
    const std::string* v = std::get_if<std::string>(&At(key));
    if (v == nullptr) Raise(key, Must(key, "a string"), 3);
    return *v;
  }
  std::string Choice(std::string_view key, const std::vector<std::string>& choices,
                     bool required) const override {
    const std::string v = String(key, required);
    for (const std::string& c : choices)
      if (c == v) return v;
    std::string message = Must(key, "one of the choices, not '");
    message.append(v).append("'");
    Raise(key, message, 3);
  }
  std::vector<double> Numbers(std::string_view key, size_t min_count, size_t max_count,
                              const NumberRule& rule) const override {
    const auto* v = std::get_if<std::vector<double>>(&At(key));
    if (v == nullptr || v->size() < min_count || v->size() > max_count)
      Raise(key, Must(key, "a list of numbers of the right length"), 3);
    for (double x : *v) CheckNumber(key, x, rule);
    return *v;
  }
  Vec3 Vector3(std::string_view key, const NumberRule& rule, bool required) const override {
    if (!Present(key, required)) return {};
    const std::vector<double> v = Numbers(key, 3, 3, rule);
    return {v[0], v[1], v[2]};
  }
  std::vector<Vec3> Vector3List(std::string_view key, size_t, const NumberRule&,
                                bool) const override {
    Raise(key, "FakeReader: no lists of vectors", 3);
  }
  [[noreturn]] void FailAtElement(std::string_view key, size_t index,
                                  const std::string& message) const override {
    std::string text = "[";
    text.append(std::to_string(index)).append("] ").append(message);
    Raise(key, text, 3);
  }
  std::vector<std::string> Strings(std::string_view key, size_t max_count,
                                   bool required) const override {
    if (!Present(key, required)) return {};
    if (const auto* one = std::get_if<std::string>(&At(key))) return {*one};
    const auto* v = std::get_if<std::vector<std::string>>(&At(key));
    if (v == nullptr || v->size() > max_count) Raise(key, Must(key, "a list of strings"), 3);
    return *v;
  }
  std::string Where(std::string_view key) const override { return Position(key, 3); }
  [[noreturn]] void Fail(std::string_view key, const std::string& message) const override {
    Raise(key, message, 3);
  }
  [[noreturn]] void FailAtKey(std::string_view key, const std::string& message) const override {
    Raise(key, message, 1);
  }
  std::shared_ptr<const TriangleMesh> Mesh(std::string_view key, const Vec3&) const override {
    Raise(key, "FakeReader: no meshes", 3);
  }
  const ModuleRegistry* registry() const override { return registry_; }
  std::vector<std::unique_ptr<ObjectReader>> Items(std::string_view) const override { return {}; }
  void Expect(std::span<const std::string>) const override {}

  void set_registry(const ModuleRegistry* registry) { registry_ = registry; }

 private:
  // "model.yaml:<line>:<column>" of `key` (line 1 for an absent key).
  std::string Position(std::string_view key, int column) const {
    const auto it = lines_.find(std::string(key));
    std::string where = "model.yaml:";
    where.append(std::to_string(it == lines_.end() ? 1 : it->second)).append(":");
    return where.append(std::to_string(column));
  }
  [[noreturn]] void Raise(std::string_view key, const std::string& message, int column) const {
    throw Error(Position(key, column).append(": ").append(message));
  }
  // "'key' must be <what>".
  static std::string Must(std::string_view key, const char* what) {
    std::string message = "'";
    message.append(key).append("' must be ").append(what);
    return message;
  }
  bool Present(std::string_view key, bool required) const {
    if (Has(key)) return true;
    if (required) Raise("", Missing(key), 1);
    return false;
  }
  const Value& At(std::string_view key) const {
    const auto it = values_.find(std::string(key));
    if (it == values_.end()) Raise("", Missing(key), 1);
    return it->second;
  }
  static std::string Missing(std::string_view key) {
    std::string message = "missing '";
    return message.append(key).append("'");
  }
  void CheckNumber(std::string_view key, double v, const NumberRule& rule) const {
    const bool low = rule.min_exclusive ? !(v > rule.min) : !(v >= rule.min);
    if (!std::isfinite(v) || low || !(v <= rule.max)) Raise(key, Must(key, rule.text), 3);
  }

  std::map<std::string, Value> values_;
  std::map<std::string, int> lines_;
  const ModuleRegistry* registry_ = nullptr;
};

}  // namespace swarmsim::testing
