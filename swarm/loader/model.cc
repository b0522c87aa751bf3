#include "swarm/loader/model.h"

#include <lauxlib.h>
#include <lua.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

#include "framework/error.h"
#include "framework/lua_evaluator.h"
#include "framework/lua_file_text.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "swarm/loader/object_reader.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// Bounds that keep a malformed (or alias-looped) model from exhausting memory or the stack.
constexpr int kMaxDepth = 32;
constexpr int kMaxObjects = 10000;
constexpr int64_t kMaxRingCount = 1024;

constexpr double kDegToRad = M_PI / 180.0;

const std::vector<std::string> kCommonKeys = {
    "name", "type", "position", "orientation_deg", "heading_deg", "children", "script", "if"};
// Two loader-only types: a ring of proximity sensors, and a plugin sensor (a
// dummy tagged with the sensor type a plugin registers).
// proximity_ring's keys; a ring that takes every key of its sensor type
// (light_sensor_ring) takes these but `range`, `noise`, `noise_uniform`,
// `failure_probability` and the proximity response keys (its type has the
// first four, and no response).
const std::vector<std::string> kRingKeys = {"name",
                                            "type",
                                            "count",
                                            "radius",
                                            "height",
                                            "range",
                                            "start_angle_deg",
                                            "noise",
                                            "noise_uniform",
                                            "failure_probability",
                                            "response",
                                            "response_incidence",
                                            "if"};
// The loader's rings (shorthands for `count` sensors round the parent's z
// axis), each of a module's sensor type found by name: proximity_ring
// (modules/proximity: each ray, its +z, points outwards; of the sensor's
// keys only `range` and the noise keys) and light_sensor_ring
// (modules/light: each sensor's +x points outwards; every light_sensor key).
struct RingKind {
  const char* name;         // the world-file type
  const char* sensor_type;  // its sensors'
  bool z_outwards;          // the sensor's +z points outwards (else its +x)
  bool all_sensor_keys;     // the ring takes every key of the sensor type (else kRingKeys)
  const char* what;         // "proximity ring": messages
};
constexpr RingKind kRings[] = {
    {"proximity_ring", "proximity_sensor", true, false, "proximity ring"},
    {"light_sensor_ring", "light_sensor", false, true, "light sensor ring"},
};
const RingKind* FindRing(const std::string& type) {
  for (const RingKind& ring : kRings)
    if (type == ring.name) return &ring;
  return nullptr;
}
// A set of ground sensors (modules/ground_sensor's type), on a ring or at
// listed points, with the keys of every ground sensor besides these.
const std::vector<std::string> kGroundArrayKeys = {
    "name", "type", "count", "radius", "start_angle_deg", "points", "height", "if"};
constexpr char kGroundSensorType[] = "ground_sensor";

// The object types a model may use: every type of the scene (the built-in
// ones, then the registry's, in listing order; object_type.h), with
// proximity_ring (the loader's shorthand for a ring of sensors) after
// proximity_sensor, and ground_array after ground_sensor, when there are.
struct TypeList {
  std::vector<const ObjectTypeDescriptor*> types;  // by ObjectType value
  std::vector<std::string> names;                  // as world files write them

  explicit TypeList(const ModuleRegistry* registry) {
    const auto core = CoreObjectTypes();
    types.assign(core.begin(), core.end());
    if (registry != nullptr)
      types.insert(types.end(), registry->object_types().begin(), registry->object_types().end());
    for (const size_t t : ListingOrder(types)) {
      names.push_back(types[t]->name);
      for (const RingKind& ring : kRings)
        if (names.back() == ring.sensor_type) {
          names.push_back(ring.name);
          break;
        }
      if (names.back() == kGroundSensorType) names.push_back("ground_array");
    }
  }
  // The type named `name` (one of `names` but a ring and ground_array).
  ObjectType Find(const std::string& name) const {
    for (size_t t = 0; t < types.size(); ++t)
      if (name == types[t]->name) return static_cast<ObjectType>(t);
    return ObjectType::kDummy;
  }
  // The keys an object of the type named `name` takes.
  std::vector<std::string> KeysOf(const std::string& name) const {
    if (name == "ground_array") {
      std::vector<std::string> keys = kGroundArrayKeys;
      for (const ObjectKey& key : types[static_cast<size_t>(Find(kGroundSensorType))]->keys)
        keys.push_back(key.name);
      return keys;
    }
    const RingKind* ring = FindRing(name);
    if (ring != nullptr && !ring->all_sensor_keys) return kRingKeys;
    if (ring != nullptr) {
      std::vector<std::string> keys;
      for (const std::string& key : kRingKeys)
        if (key != "range" && key != "noise" && key != "noise_uniform" &&
            key != "failure_probability" && key != "response" && key != "response_incidence")
          keys.push_back(key);
      for (const ObjectKey& key : types[static_cast<size_t>(Find(ring->sensor_type))]->keys)
        keys.push_back(key.name);
      return keys;
    }
    std::vector<std::string> keys = kCommonKeys;
    for (const ObjectKey& key : types[static_cast<size_t>(Find(name))]->keys)
      keys.push_back(key.name);
    return keys;
  }
  // The keys of every type, once each (for an object without a 'type').
  std::vector<std::string> AllKeys() const {
    std::vector<std::string> all;
    for (const std::string& name : names)
      for (const std::string& key : KeysOf(name))
        if (std::find(all.begin(), all.end(), key) == all.end()) all.push_back(key);
    return all;
  }
};

// A new row of `type`'s default values, in a table of its own (null for a
// type without rows).
std::shared_ptr<RowTable> NewRow(const ObjectTypeDescriptor& type) {
  if (type.make_rows == nullptr) return nullptr;
  std::shared_ptr<RowTable> row = type.make_rows(type);
  row->Append(nullptr, 0);
  return row;
}

struct Builder {
  const ModelFile& model;
  const ValueReader& values;
  ScriptCache* scripts;
  int objects = 0;
  MeshCache* meshes = nullptr;
  const ModuleRegistry* registry = nullptr;
  TypeList types{registry};

  void Count(const Field& field, int n) {
    objects += n;
    if (objects > kMaxObjects)
      values.Fail(field, "model '" + model.name + "' has more than " + std::to_string(kMaxObjects) +
                             " objects (an alias loop?)");
  }

  // Parses the object at `field` (a ring gives several) into `out`.
  void Object(const Field& field, int depth, bool is_root, std::vector<ObjectSpec>* out) {
    if (depth > kMaxDepth)
      values.Fail(field, "objects nested more than " + std::to_string(kMaxDepth) +
                             " levels deep (an alias loop?)");
    const std::string root_what = "the root object of model '" + model.name + "'";
    Fields fields(values.file(), field,
                  is_root ? root_what : "an object of model '" + model.name + "'");
    // `if: false` (usually `if: $with_x`) leaves the object and its subtree
    // out. It is still read, so that its mistakes are errors, unless its
    // type is none this world has (a device of a module the registry lacks).
    bool enabled = true;
    if (fields.Has("if")) {
      if (is_root) values.Fail(fields.Get("if"), "the root object of a model cannot have 'if'");
      enabled = values.Bool(fields.Get("if"));
      if (!enabled && fields.Has("type") && fields.Get("type").node.IsScalar() &&
          std::find(types.names.begin(), types.names.end(), fields.Get("type").node.Scalar()) ==
              types.names.end())
        return;
    }
    // A misspelled 'type' or 'name' is an unknown key (with a suggestion),
    // not a missing one: without them, check the keys first.
    if (!fields.Has("type")) fields.Expect(types.AllKeys());
    const Field type_field = fields.Require("type");
    const std::string type = values.Choice(type_field, types.names);
    // The root is named after each copy in the scene (footbot#0, ...); its
    // name here is optional and only labels it in messages.
    std::string name = model.name;
    if (!is_root || fields.Has("name")) {
      if (!fields.Has("name")) fields.Expect(types.KeysOf(type));
      const Field name_field = fields.Require("name");
      name = values.String(name_field);
      CheckObjectName(values, name_field, name);
    }
    const RingKind* ring = FindRing(type);
    const std::string what = is_root ? root_what
                                     : (ring != nullptr          ? std::string(ring->what) + " '"
                                        : type == "ground_array" ? "ground array '"
                                                                 : "object '") +
                                           name + "'";
    Fields named(values.file(), field, what);

    if (ring != nullptr && is_root)
      values.Fail(type_field,
                  "a " + std::string(ring->what) + " cannot be the root object of a model");
    if (type == "ground_array" && is_root)
      values.Fail(type_field, "a ground array cannot be the root object of a model");
    named.Expect(types.KeysOf(type));
    if (!enabled) {  // read, then dropped
      std::vector<ObjectSpec> dropped;
      const int counted = objects;
      ObjectUnconditional(named, field, depth, type, ring, name, &dropped);
      objects = counted;
      return;
    }
    ObjectUnconditional(named, field, depth, type, ring, name, out);
  }

  // The object `named` (already checked) into `out`.
  void ObjectUnconditional(const Fields& named, const Field& field, int depth,
                           const std::string& type, const RingKind* ring, const std::string& name,
                           std::vector<ObjectSpec>* out) {
    if (ring != nullptr) {
      Ring(*ring, named, name, out);
      return;
    }
    if (type == "ground_array") {
      GroundArray(named, field, name, out);
      return;
    }

    ObjectSpec spec;
    spec.name = name;
    spec.X_PO = ReadPose(values, named);
    // The type's own reader fills its row (framework/types/, object_type.h).
    spec.type = types.Find(type);
    const ObjectTypeDescriptor& descriptor = *types.types[static_cast<size_t>(spec.type)];
    spec.row = NewRow(descriptor);
    if (descriptor.read != nullptr)
      descriptor.read(descriptor, FieldsObjectReader(values, named, meshes, registry),
                      spec.row->At(0));
    Count(field, 1);
    if (named.Has("script")) {
      // script: file.lua, or script: {file: file.lua, explicit: true}.
      Field script = named.Get("script");
      if (script.node.IsMap()) {
        Fields s(values.file(), script, "'script'");
        s.Expect({"file", "explicit"});
        if (s.Has("explicit")) spec.script_explicit = values.Bool(s.Get("explicit"));
        script = s.Require("file");
      }
      const std::string text = values.String(script);
      if (text.empty()) values.Fail(script, "'script' must be a file name");
      spec.script = scripts->Get(model.file.path().parent_path() / text,
                                 values.file().Where(script.mark), text);
    }
    for (const Field& child : ListElements(values.file(), named.Get("children"), "objects"))
      Object(child, depth + 1, false, &spec.children);
    out->push_back(std::move(spec));
  }

  // `count` sensors named `name` in a ring around the parent's z axis:
  // sensor i at angle start + 2 pi i / count counter-clockwise from the
  // parent's +x, its z axis (a proximity ray) or its x axis (a light
  // sensor) pointing radially outwards.
  void Ring(const RingKind& kind, const Fields& f, const std::string& name,
            std::vector<ObjectSpec>* out) {
    const int64_t count = values.Integer(f.Require("count"), 1, kMaxRingCount);
    const double radius = values.Number(f.Require("radius"), kNonNegativeLength);
    const double height = f.Has("height") ? values.Number(f.Get("height"), kCoordinate) : 0.0;
    // Each sensor of the ring reads the ring's keys as its type does.
    const ObjectType ring_type = types.Find(kind.sensor_type);
    const ObjectTypeDescriptor& sensor_type = *types.types[static_cast<size_t>(ring_type)];
    const std::shared_ptr<RowTable> sensor = NewRow(sensor_type);
    sensor_type.read(sensor_type, FieldsObjectReader(values, f, meshes, registry), sensor->At(0));
    const double start = f.Has("start_angle_deg")
                             ? values.Number(f.Get("start_angle_deg"), kAngleDeg) * kDegToRad
                             : 0;
    Count(f.Get("count"), static_cast<int>(count));
    // Ry(90 deg) turns z onto x; the yaw then turns x onto the ray's direction.
    const Quat z_to_x = Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
    for (int64_t i = 0; i < count; ++i) {
      const double theta = start + 2 * M_PI * static_cast<double>(i) / static_cast<double>(count);
      ObjectSpec spec;
      spec.name = name;
      spec.type = ring_type;
      spec.row = sensor;  // shared: specs are not changed after they are read
      spec.X_PO = {{radius * std::cos(theta), radius * std::sin(theta), height},
                   kind.z_outwards ? Quat::FromYaw(theta) * z_to_x : Quat::FromYaw(theta)};
      out->push_back(std::move(spec));
    }
  }

  // Ground sensors named `name`, in the parent's frame at z = height: either
  // `count` on a circle of `radius` (sensor i at angle start + 2 pi i / count
  // counter-clockwise from +x), or one at each of `points` ([x, y] m). Each
  // reads the array's ground-sensor keys (mode, threshold, noise, ...).
  void GroundArray(const Fields& f, const Field& field, const std::string& name,
                   std::vector<ObjectSpec>* out) {
    std::vector<std::pair<double, double>> xy;
    if (f.Has("points")) {
      for (const char* ring_key : {"count", "radius", "start_angle_deg"})
        if (f.Has(ring_key))
          values.Fail(f.Get(ring_key), std::string("a ground array takes 'points' or '") +
                                           ring_key + "' (a ring), not both");
      const std::vector<Field> points = ListElements(values.file(), f.Get("points"), "points");
      if (points.empty() || points.size() > static_cast<size_t>(kMaxRingCount))
        values.Fail(f.Get("points"),
                    "'points' must list 1 to " + std::to_string(kMaxRingCount) + " points [x, y]");
      for (const Field& point : points) {
        const std::vector<double> p = values.Numbers(point, 2, 2, kCoordinate);
        xy.emplace_back(p[0], p[1]);
      }
    } else {
      if (!f.Has("count"))
        values.Fail(field, "a ground array needs 'points: [[x, y], ...]' or 'count' and 'radius'");
      const int64_t count = values.Integer(f.Require("count"), 1, kMaxRingCount);
      const double radius = values.Number(f.Require("radius"), kNonNegativeLength);
      const double start = f.Has("start_angle_deg")
                               ? values.Number(f.Get("start_angle_deg"), kAngleDeg) * kDegToRad
                               : 0;
      for (int64_t i = 0; i < count; ++i) {
        const double theta = start + 2 * M_PI * static_cast<double>(i) / static_cast<double>(count);
        xy.emplace_back(radius * std::cos(theta), radius * std::sin(theta));
      }
    }
    const double height = f.Has("height") ? values.Number(f.Get("height"), kCoordinate) : 0.0;
    const ObjectType sensor_type = types.Find(kGroundSensorType);
    const ObjectTypeDescriptor& descriptor = *types.types[static_cast<size_t>(sensor_type)];
    const std::shared_ptr<RowTable> sensor = NewRow(descriptor);
    descriptor.read(descriptor, FieldsObjectReader(values, f, meshes, registry), sensor->At(0));
    Count(field, static_cast<int>(xy.size()));
    for (const auto& [x, y] : xy) {
      ObjectSpec spec;
      spec.name = name;
      spec.type = sensor_type;
      spec.row = sensor;  // shared: specs are not changed after they are read
      spec.X_PO = {{x, y, height}, {}};
      out->push_back(std::move(spec));
    }
  }
};

}  // namespace

// --- Scripts ----------------------------------------------------------------------

std::shared_ptr<const ScriptSource> ScriptCache::Get(const fs::path& path, const std::string& where,
                                                     const std::string& text) {
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (ec) key = fs::absolute(path, ec).lexically_normal();
  if (auto it = sources_.find(key); it != sources_.end()) return it->second;
  auto source = std::make_shared<ScriptSource>();
  source->path = DisplayPath(path);
  source->code = LuaFileText(ReadFileOrThrow(path, "script file", where, text));
  // Compiled Lua (luac's output): it said "script attempt to load a binary
  // chunk (mode is 't')". Scripts load as source only.
  if (source->code.starts_with("\x1bLua"))
    throw Error(where + ": script '" + source->path +
                "' is compiled Lua (a binary chunk, as luac writes it); scripts are read as "
                "source only: give its .lua source");
  // A script that does not parse is the world's error, found as it loads
  // (exit 2, the file's line), not at start as every robot's.
  {
    LimitedLua lua{"the script's syntax check", size_t{256} << 20, 1000};
    // Chunk "?", named in full below (Lua shortens long chunk names).
    if (luaL_loadbufferx(lua.L(), source->code.data(), source->code.size(), "=?", "t") != LUA_OK) {
      const char* text = lua_tostring(lua.L(), -1);
      std::string message = text != nullptr ? text : "?: does not parse";
      if (message.starts_with("?:")) message.replace(0, 1, source->path);
      throw Error(where + ": script " + message);
    }
  }
  sources_.emplace(key, source);
  return source;
}

// --- Shapes and poses ----------------------------------------------------------------

const std::vector<std::string>& ShapeKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (const ObjectKey& key : CoreObjectTypes()[static_cast<size_t>(ObjectType::kShape)]->keys)
      out.push_back(key.name);
    return out;
  }();
  return keys;
}

const std::vector<std::string>& PoseKeys() {
  static const std::vector<std::string> keys = {"position", "orientation_deg", "heading_deg"};
  return keys;
}

ShapeData ReadShape(const ValueReader& values, const Fields& f, MeshCache* meshes) {
  Shared<ShapeData> shape;  // the type's row
  const ObjectTypeDescriptor& type = *CoreObjectTypes()[static_cast<size_t>(ObjectType::kShape)];
  type.read(type, FieldsObjectReader(values, f, meshes, nullptr), &shape);
  return *shape;
}

Pose ReadPose(const ValueReader& values, const Fields& f) {
  Pose X;
  if (f.Has("position")) X.p = values.Vector3(f.Get("position"), kCoordinate);
  X.q = ReadOrientation(values, f);
  return X;
}

Quat ReadOrientation(const ValueReader& values, const Fields& f) {
  Quat q;
  if (f.Has("orientation_deg") && f.Has("heading_deg"))
    values.Fail(f.Get("heading_deg"),
                "give either 'orientation_deg: [roll, pitch, yaw]' or 'heading_deg', not both");
  if (f.Has("orientation_deg")) {
    const Vec3 rpy = values.Vector3(f.Get("orientation_deg"), kAngleDeg) * kDegToRad;
    q = Quat::FromRollPitchYaw(rpy.x, rpy.y, rpy.z);
  } else if (f.Has("heading_deg")) {
    q = Quat::FromYaw(values.Number(f.Get("heading_deg"), kAngleDeg) * kDegToRad);
  }
  return q;
}

// --- Model files ---------------------------------------------------------------------

bool IsParameterName(std::string_view name) {
  static const char* const kLuaKeywords[] = {
      "and",      "break",  "do",   "else", "elseif", "end",  "false", "for",
      "function", "goto",   "if",   "in",   "local",  "nil",  "not",   "or",
      "repeat",   "return", "then", "true", "until",  "while"};
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  for (const char* k : kLuaKeywords)
    if (name == k) return false;
  return true;
}

ModelFile ReadModelFile(YamlFile file, const std::string& used_by,
                        std::span<const std::string> section_keys) {
  ModelFile model{std::move(file), {}, {}, {}, {}, {}, {}, {}, {}};
  const YamlFile& f = model.file;
  Field top{"model file", f.root(), f.root().Mark().is_null() ? YAML::Mark() : f.root().Mark(), {}};
  if (!f.root().IsMap()) {
    // XML where YAML was expected: a URDF not named .urdf, or a xacro.
    const bool xml = f.root().IsScalar() && f.root().Scalar().starts_with("<");
    f.Fail(top.mark,
           "a model file must be a mapping with 'model', 'parameters' and 'objects' (got " +
               Describe(f.root()) + "; used by " + used_by + ")" +
               (xml ? "; this is XML: a URDF is read as one when its name ends in .urdf (a "
                      ".xacro file is expanded first: xacro robot.urdf.xacro > robot.urdf)"
                    : ""));
  }
  Fields fields(f, top, "the model file");
  // The loader's keys, then the modules' sections (read with the model's values).
  std::vector<std::string> keys = {"model", "description", "parameters", "objects"};
  keys.insert(keys.end(), section_keys.begin(), section_keys.end());
  fields.Expect(keys);
  model.top = top;
  const Field name_field = fields.Require("model");
  if (!name_field.node.IsScalar())
    f.Fail(name_field.mark,
           "'model' must be the model's name (got " + Describe(name_field.node) + ")");
  model.name = name_field.node.Scalar();
  if (model.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                   "0123456789_-") != std::string::npos)
    f.Fail(name_field.mark,
           "model name '" + model.name +
               "' may use only letters, digits, '_' and '-' (it names the copies: " +
               "name#0, name#1, ...)");
  if (fields.Has("description") && !fields.Get("description").node.IsScalar())
    f.Fail(fields.Get("description").mark, "'description' must be text");

  // Parameters: name -> default, or name -> {default, unit, description}.
  const Field params = fields.Get("parameters");
  if (params.present()) {
    Fields decls(f, params, "the parameters of model '" + model.name + "'");
    for (const Field& p : decls.fields()) {
      if (!IsParameterName(p.name))
        f.Fail(p.key_mark, "parameter name '" + p.name +
                               "' must be a Lua identifier (letters, digits, '_'; not a keyword)");
      ModelParameterDecl decl{p.name, p, "", "", p.key_mark};
      if (p.node.IsMap()) {
        Fields d(f, p, "parameter '" + p.name + "'");
        d.Expect({"default", "unit", "description", "range"});
        if (d.Has("range")) {
          // [min, max]: two literal numbers, min <= max.
          const Field range = d.Get("range");
          if (!range.node.IsSequence() || range.node.size() != 2)
            f.Fail(range.mark,
                   "'range' must be [min, max], two numbers (got " +
                       (range.node.IsSequence() ? "a list of " + std::to_string(range.node.size())
                                                : Describe(range.node)) +
                       ")");
          double bounds[2];
          for (size_t i = 0; i < 2; ++i) {
            const YAML::Node bound = range.node[i];
            const ParamValue value =
                bound.IsScalar() ? ParseScalar(bound.Scalar(), false) : ParamValue(std::string());
            if (!std::holds_alternative<double>(value))
              f.Fail(bound.Mark().is_null() ? range.mark : bound.Mark(),
                     "'range' must be [min, max], two numbers: its " +
                         std::string(i == 0 ? "min" : "max") + " is not a number (got " +
                         Describe(bound) + ")");
            bounds[i] = std::get<double>(value);
          }
          if (!(bounds[0] <= bounds[1]))
            f.Fail(range.mark, "'range' must be [min, max] with min <= max (got min " +
                                   FormatNumber(bounds[0]) + " > max " + FormatNumber(bounds[1]) +
                                   ")");
          decl.has_range = true;
          decl.min = bounds[0];
          decl.max = bounds[1];
        }
        decl.default_value = d.Require("default");
        decl.default_value.name = p.name;
        for (const char* key : {"unit", "description"})
          if (d.Has(key) && !d.Get(key).node.IsScalar())
            f.Fail(d.Get(key).mark, "'" + std::string(key) + "' must be text");
        decl.unit = d.Get("unit").node.Scalar();
        decl.description = d.Get("description").node.Scalar();
      } else if (!p.node.IsScalar() || !p.present()) {
        f.Fail(p.mark, "parameter '" + p.name +
                           "' must be a value or {default, unit, range, description} (got " +
                           Describe(p.node) + ")");
      }
      model.parameters.push_back(std::move(decl));
    }
  }

  // The root object: a mapping, or (equivalently) a list holding just it.
  const Field objects = fields.Require("objects");
  if (objects.node.IsMap()) {
    model.root = objects;
  } else {
    const std::vector<Field> roots = ListElements(f, objects, "objects");
    if (roots.size() != 1)
      f.Fail(objects.mark,
             "'objects' is the model's root object (the body copies are placed by), "
             "with the others under its 'children' (got a list of " +
                 std::to_string(roots.size()) + ")");
    model.root = roots[0];
  }
  return model;
}

ObjectSpec ResolveModel(const ModelFile& model, const ValueReader& values, ScriptCache* scripts,
                        MeshCache* meshes, const ModuleRegistry* registry) {
  if (model.imported) return *model.imported;
  Builder builder{model, values, scripts, 0, meshes, registry};
  std::vector<ObjectSpec> out;
  builder.Object(model.root, 0, true, &out);
  return std::move(out.front());
}

std::vector<ObjectSpec> ReadSceneObjects(const YamlFile& file, const Field& list,
                                         const ValueReader& values, ScriptCache* scripts,
                                         MeshCache* meshes, const ModuleRegistry* registry) {
  ModelFile scene_model{file, "the world", {}, list, {}, {}, {}, {}, {}};
  Builder builder{scene_model, values, scripts, 0, meshes, registry};
  std::vector<ObjectSpec> out;
  for (const Field& element : ListElements(file, list, "objects"))
    builder.Object(element, 1, false, &out);
  return out;
}

// --- Scene ----------------------------------------------------------------------------

ObjectId AddToScene(const ObjectSpec& spec, ObjectId parent, Scene* scene) {
  const ObjectId id = scene->AddObject(spec.type, spec.name, parent, spec.X_PO,
                                       spec.row ? spec.row->At(0) : nullptr);
  if (spec.script) scene->AttachScript(id, spec.script, spec.script_explicit);
  for (const ObjectSpec& child : spec.children) AddToScene(child, id, scene);
  return id;
}

namespace {

void Accumulate(const ObjectSpec& spec, const Pose& X_RP, Footprint* fp, bool* any) {
  const Pose X_RO = X_RP * spec.X_PO;
  // A shape neither seen nor touched (an imported link's mass carrier, a
  // 1 mm sphere) is no part of the footprint: copies stood 1 mm up on it.
  if (const ShapeData* shape = spec.AsShape(); shape && (shape->collidable || shape->visible)) {
    const ShapeData& s = *shape;
    Vec3 half;  // half extents in the shape's frame
    switch (s.kind) {
      case ShapeKind::kBox: half = s.size * 0.5; break;
      case ShapeKind::kCylinder:
      case ShapeKind::kCapsule: half = {s.size.x, s.size.x, s.size.z / 2}; break;
      case ShapeKind::kSphere: half = {s.size.x, s.size.x, s.size.x}; break;
      case ShapeKind::kMesh: half = s.size * 0.5; break;  // a centred box around it
    }
    // Axis-aligned half extents of the rotated shape, in the root's frame.
    const Vec3 cx = X_RO.q.Rotate({half.x, 0, 0}), cy = X_RO.q.Rotate({0, half.y, 0}),
               cz = X_RO.q.Rotate({0, 0, half.z});
    const Vec3 e{std::abs(cx.x) + std::abs(cy.x) + std::abs(cz.x),
                 std::abs(cx.y) + std::abs(cy.y) + std::abs(cz.y),
                 std::abs(cx.z) + std::abs(cy.z) + std::abs(cz.z)};
    const double centre = std::hypot(X_RO.p.x, X_RO.p.y);
    const Vec3 z = X_RO.q.Rotate({0, 0, 1});
    double radius;
    if (s.kind == ShapeKind::kSphere || std::abs(z.z) > 1 - 1e-9) {
      // Upright (or a sphere): the shape's own footprint circle is exact.
      radius = centre + s.BoundingRadius();
    } else {
      radius = std::hypot(std::abs(X_RO.p.x) + e.x, std::abs(X_RO.p.y) + e.y);
    }
    double bottom = X_RO.p.z - e.z, top = X_RO.p.z + e.z;
    if (s.kind == ShapeKind::kMesh && s.mesh) {  // exact over its vertices
      radius = 0;
      bottom = std::numeric_limits<double>::infinity();
      top = -bottom;
      for (const Vec3& v : s.mesh->vertices()) {
        const Vec3 p = X_RO * v;
        radius = std::max(radius, std::hypot(p.x, p.y));
        bottom = std::min(bottom, p.z);
        top = std::max(top, p.z);
      }
    }
    if (!*any) {
      fp->radius = radius;
      fp->bottom = bottom;
      fp->top = top;
      *any = true;
    } else {
      fp->radius = std::max(fp->radius, radius);
      fp->bottom = std::min(fp->bottom, bottom);
      fp->top = std::max(fp->top, top);
    }
  }
  const JointData* joint = spec.As<JointData>(ObjectType::kJoint);
  const Pose X_RC = joint != nullptr ? X_RO * joint->Motion() : X_RO;
  for (const ObjectSpec& child : spec.children) Accumulate(child, X_RC, fp, any);
}

}  // namespace

Footprint ComputeFootprint(const ObjectSpec& root) {
  Footprint fp;
  bool any = false;
  // In the model's frame: the root's own pose (if the file gives one) included.
  Accumulate(root, Pose{}, &fp, &any);
  return fp;
}

}  // namespace swarmsim::loader
