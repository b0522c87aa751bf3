// A model entry's `filters:` list written in C++ for the filter tests: an
// ObjectReader whose items hold numbers and names, and whose errors throw
// swarmsim::Error naming the item and key ("filters[1].type: ..."). The
// world-file side (file:line:column) is tested through the loader
// (tests/swarm/loader/vision_filters_loader_test.cc).
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
#include "framework/suggest.h"

namespace swarmsim::testing {

// One map of the list: {type: NAME, key: number or [numbers], ...}.
struct FilterItem {
  std::string type;
  std::map<std::string, std::vector<double>> numbers;
};

class FilterListReader final : public ObjectReader {
 public:
  // The entry (its `filters` key holds `items`), or one item.
  FilterListReader(std::vector<FilterItem> items, const ModuleRegistry* registry)
      : where_("entry"), items_(std::move(items)), registry_(registry) {}
  FilterListReader(const FilterItem& item, std::string where, const ModuleRegistry* registry)
      : where_(std::move(where)), numbers_(item.numbers), registry_(registry) {
    if (!item.type.empty()) texts_["type"] = item.type;
  }

  bool Has(std::string_view key) const override {
    return numbers_.count(std::string(key)) || texts_.count(std::string(key)) ||
           (key == "filters" && !items_.empty());
  }
  double Number(std::string_view key, const NumberRule& rule, bool) const override {
    const double v = Get(key).at(0);
    if (v < rule.min || v > rule.max || (rule.min_exclusive && v == rule.min))
      Fail(key, "must be " + std::string(rule.text));
    return v;
  }
  int64_t Integer(std::string_view key, int64_t min, int64_t max) const override {
    const double v = Get(key).at(0);
    if (v < static_cast<double>(min) || v > static_cast<double>(max) || v != std::floor(v))
      Fail(key, "must be an integer from " + std::to_string(min) + " to " + std::to_string(max));
    return static_cast<int64_t>(v);
  }
  bool Bool(std::string_view key) const override { return Get(key).at(0) != 0; }
  std::string String(std::string_view key, bool) const override {
    auto it = texts_.find(std::string(key));
    if (it == texts_.end()) Fail(key, "is required");
    return it->second;
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
    if (v.size() < min_count || v.size() > max_count) Fail(key, "wrong count");
    for (double x : v)
      if (x < rule.min || x > rule.max) Fail(key, "must be " + std::string(rule.text));
    return v;
  }
  Vec3 Vector3(std::string_view key, const NumberRule& rule, bool) const override {
    const std::vector<double> v = Numbers(key, 3, 3, rule);
    return {v[0], v[1], v[2]};
  }
  std::vector<std::string> Strings(std::string_view key, size_t, bool) const override {
    return {String(key, false)};
  }
  std::string Where(std::string_view key) const override { return where_ + "." + std::string(key); }
  [[noreturn]] void Fail(std::string_view key, const std::string& message) const override {
    throw Error(Where(key) + ": " + message);
  }
  [[noreturn]] void FailAtKey(std::string_view key, const std::string& message) const override {
    Fail(key, message);
  }
  std::vector<Vec3> Vector3List(std::string_view key, size_t, const NumberRule&,
                                bool) const override {
    Fail(key, "takes no list of [x, y, z] here");
  }
  [[noreturn]] void FailAtElement(std::string_view key, size_t,
                                  const std::string& message) const override {
    Fail(key, message);
  }
  std::shared_ptr<const TriangleMesh> Mesh(std::string_view, const Vec3&) const override {
    return nullptr;
  }
  const ModuleRegistry* registry() const override { return registry_; }
  std::vector<std::unique_ptr<ObjectReader>> Items(std::string_view key) const override {
    std::vector<std::unique_ptr<ObjectReader>> out;
    if (key != "filters") return out;
    for (size_t i = 0; i < items_.size(); ++i)
      out.push_back(std::make_unique<FilterListReader>(
          items_[i], "filters[" + std::to_string(i) + "]", registry_));
    return out;
  }
  void Expect(std::span<const std::string> known) const override {
    std::vector<std::string> keys;
    for (const auto& [k, v] : numbers_) keys.push_back(k);
    for (const auto& [k, v] : texts_) keys.push_back(k);
    for (const std::string& k : keys)
      if (std::find(known.begin(), known.end(), k) == known.end())
        Fail(k, "unknown key '" + k + "'" + Suggest(k, known));
  }

 private:
  const std::vector<double>& Get(std::string_view key) const {
    auto it = numbers_.find(std::string(key));
    if (it == numbers_.end()) Fail(key, "is required");
    return it->second;
  }

  std::string where_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::string> texts_;
  std::vector<FilterItem> items_;
  const ModuleRegistry* registry_;
};

}  // namespace swarmsim::testing
