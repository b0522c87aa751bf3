#include "framework/plugin_object_type.h"

#include <cmath>
#include <cstdio>
#include <deque>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"

namespace swarmsim {
namespace {

struct PluginRow {
  std::vector<double> values;  // one per key, in the type's order
};

// What the shared hooks need of one plugin type: its keys (owned).
struct PluginTypeData {
  std::string name, description;
  // Per key: its name, default, range ("a number from 0 to 10") and doc
  // (a deque: stable addresses for the ObjectKeys below).
  std::deque<std::string> texts;
  std::vector<ObjectKey> keys;
  std::vector<SwarmsimObjectKey> rules;
};

// A descriptor and the data its hooks read, kept together.
struct PluginType {
  PluginTypeData data;
  ObjectTypeDescriptor descriptor;
};

const PluginTypeData& Data(const ObjectTypeDescriptor& type) {
  return *static_cast<const PluginTypeData*>(type.context);
}

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<PluginRow>>();
}

void Scale(const ObjectTypeDescriptor& type, void* row, double s, ScaleContext*) {
  const PluginTypeData& data = Data(type);
  std::vector<double>& values = static_cast<PluginRow*>(row)->values;
  for (size_t k = 0; k < values.size() && k < data.rules.size(); ++k)
    values[k] *= std::pow(s, data.rules[k].length_power);
}

void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& table = static_cast<const Rows<PluginRow>&>(*scene.rows(type));
  for (size_t r = 0; r < table.rows.size(); ++r) {
    h->AddValue(table.owners[r]);
    for (double v : table.rows[r].values) h->AddValue(v);
  }
}

void Read(const ObjectTypeDescriptor& type, const ObjectReader& reader, void* row) {
  const PluginTypeData& data = Data(type);
  std::vector<double>& values = static_cast<PluginRow*>(row)->values;
  values.clear();
  for (size_t k = 0; k < data.rules.size(); ++k) {
    const SwarmsimObjectKey& key = data.rules[k];
    values.push_back(key.default_value);
    if (reader.Has(key.name))
      values.back() = reader.Number(key.name, {data.texts[4 * k + 2].c_str(), key.min, key.max});
  }
}

}  // namespace

std::shared_ptr<const ObjectTypeDescriptor> MakePluginObjectType(
    const std::string& name, const std::string& description,
    const std::vector<SwarmsimObjectKey>& keys) {
  auto type = std::make_shared<PluginType>();
  PluginTypeData& data = type->data;
  data.name = name;
  data.description = description;
  for (const SwarmsimObjectKey& key : keys) {
    if (key.name == nullptr || key.name[0] == '\0')
      throw Error("object type '" + name + "': a key needs a name");
    if (!(key.min <= key.default_value && key.default_value <= key.max))
      throw Error("object type '" + name + "': the default of '" + key.name +
                  "' is outside its range");
    char range[96];
    std::snprintf(range, sizeof range, "a number from %g to %g", key.min, key.max);
    char default_text[32];
    std::snprintf(default_text, sizeof default_text, "%g", key.default_value);
    data.texts.push_back(key.name);
    data.texts.push_back(default_text);
    data.texts.push_back(range);  // what a value is checked against, for messages
    data.texts.push_back(key.doc != nullptr ? key.doc : "");
    SwarmsimObjectKey rule = key;
    rule.name = data.texts[data.texts.size() - 4].c_str();
    rule.doc = data.texts.back().c_str();
    data.rules.push_back(rule);
  }
  for (size_t k = 0; k < data.rules.size(); ++k)
    data.keys.push_back(
        {data.texts[4 * k].c_str(), data.texts[4 * k + 1].c_str(), data.texts[4 * k + 3].c_str()});
  type->descriptor = ObjectTypeDescriptor{
      .name = data.name.c_str(),
      .description = data.description.c_str(),
      .context = &type->data,
      .make_rows = MakeRows,
      .scale_row = Scale,
      .hash_rows = Hash,
      .keys = data.keys,
      .read = Read,
  };
  return std::shared_ptr<const ObjectTypeDescriptor>(type, &type->descriptor);
}

const std::vector<double>* PluginObjectValues(const Scene& scene, ObjectId object) {
  if (!scene.IsValid(object)) return nullptr;
  const ObjectType type = scene.type(object);
  if (scene.type_descriptor(type).make_rows != MakeRows) return nullptr;
  const auto& table = static_cast<const Rows<PluginRow>&>(*scene.rows(type));
  return &table.rows[scene.row_at(object.index())].values;
}

}  // namespace swarmsim
