#include "swarm/loader/model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

#include "framework/error.h"
#include "framework/registry.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// Bounds that keep a malformed (or alias-looped) model from exhausting memory or the stack.
constexpr int kMaxDepth = 32;
constexpr int kMaxObjects = 10000;
constexpr int64_t kMaxRingCount = 1024;

constexpr double kDegToRad = M_PI / 180.0;

const std::vector<std::string> kObjectTypes = {
    "shape",          "joint",        "dummy",        "proximity_sensor",
    "proximity_ring", "force_sensor", "paint_nozzle", "plugin_sensor"};
const std::vector<std::string> kCommonKeys = {
    "name", "type", "position", "orientation_deg", "heading_deg", "children", "script"};
const std::vector<std::string> kJointKeys = {"joint",
                                             "mode",
                                             "max_force",
                                             "max_velocity",
                                             "target_velocity",
                                             "target_position",
                                             "initial_position",
                                             "target_force",
                                             "limits"};
const std::vector<std::string> kSensorKeys = {"range"};
const std::vector<std::string> kForceSensorKeys = {"filter_samples", "force_threshold",
                                                   "torque_threshold", "break_after"};
const std::vector<std::string> kPaintNozzleKeys = {"color", "radius", "enabled"};
const std::vector<std::string> kPluginSensorKeys = {"sensor"};
const std::vector<std::string> kRingKeys = {"name",   "type",  "count",          "radius",
                                            "height", "range", "start_angle_deg"};

std::vector<std::string> Concat(std::initializer_list<const std::vector<std::string>*> lists) {
  std::vector<std::string> out;
  for (const auto* l : lists) out.insert(out.end(), l->begin(), l->end());
  return out;
}

// The keys an object of `type` (one of kObjectTypes) takes.
const std::vector<std::string>& KeysOf(const std::string& type) {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"shape", Concat({&kCommonKeys, &ShapeKeys()})},
      {"joint", Concat({&kCommonKeys, &kJointKeys})},
      {"dummy", kCommonKeys},
      {"proximity_sensor", Concat({&kCommonKeys, &kSensorKeys})},
      {"proximity_ring", kRingKeys},
      {"force_sensor", Concat({&kCommonKeys, &kForceSensorKeys})},
      {"paint_nozzle", Concat({&kCommonKeys, &kPaintNozzleKeys})},
      {"plugin_sensor", Concat({&kCommonKeys, &kPluginSensorKeys})}};
  return keys.at(type);
}

// The keys of every object type, once each (for an object without a 'type').
const std::vector<std::string>& AllObjectKeys() {
  static const std::vector<std::string> all = [] {
    std::vector<std::string> out;
    for (const std::string& type : kObjectTypes)
      for (const std::string& key : KeysOf(type))
        if (std::find(out.begin(), out.end(), key) == out.end()) out.push_back(key);
    return out;
  }();
  return all;
}

// Object names are path elements: no '/', no brackets.
void CheckObjectName(const ValueReader& values, const Field& field, const std::string& name) {
  if (name.empty() || name.find_first_of("/[]") != std::string::npos ||
      name.find_first_of(" \t\n") != std::string::npos)
    values.Fail(field, "object name '" + name +
                           "' must be non-empty, without spaces, '/', '[' or ']' (it is used in "
                           "paths such as ./leftMotor)");
}

struct Builder {
  const ModelFile& model;
  const ValueReader& values;
  ScriptCache* scripts;
  int objects = 0;
  MeshCache* meshes = nullptr;
  const ModuleRegistry* registry = nullptr;

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
    // A misspelled 'type' or 'name' is an unknown key (with a suggestion),
    // not a missing one: without them, check the keys first.
    if (!fields.Has("type")) fields.Expect(AllObjectKeys());
    const Field type_field = fields.Require("type");
    const std::string type = values.Choice(type_field, kObjectTypes);
    // The root is named after each copy in the scene (footbot#0, ...); its
    // name here is optional and only labels it in messages.
    std::string name = model.name;
    if (!is_root || fields.Has("name")) {
      if (!fields.Has("name")) fields.Expect(KeysOf(type));
      const Field name_field = fields.Require("name");
      name = values.String(name_field);
      CheckObjectName(values, name_field, name);
    }
    const std::string what =
        is_root ? root_what
                : (type == "proximity_ring" ? "proximity ring '" : "object '") + name + "'";
    Fields named(values.file(), field, what);

    if (type == "proximity_ring" && is_root)
      values.Fail(type_field, "a proximity ring cannot be the root object of a model");
    named.Expect(KeysOf(type));
    if (type == "proximity_ring") {
      Ring(named, name, out);
      return;
    }

    ObjectSpec spec;
    spec.name = name;
    spec.X_PO = ReadPose(values, named);
    if (type == "shape") {
      spec.type = ObjectType::kShape;
      spec.shape = ReadShape(values, named, meshes);
    } else if (type == "joint") {
      spec.type = ObjectType::kJoint;
      spec.joint = Joint(named);
    } else if (type == "proximity_sensor") {
      spec.type = ObjectType::kProximitySensor;
      if (named.Has("range"))
        spec.sensor.range = values.Number(named.Get("range"), kPositiveLength);
    } else if (type == "force_sensor") {
      spec.type = ObjectType::kForceSensor;
      spec.force_sensor = ForceSensor(named);
    } else if (type == "paint_nozzle") {
      spec.type = ObjectType::kPaintNozzle;
      if (named.Has("color"))
        spec.paint_nozzle.color = values.Vector3(named.Get("color"), kFraction);
      if (named.Has("radius"))
        spec.paint_nozzle.radius = values.Number(named.Get("radius"), kPositiveLength);
      if (named.Has("enabled")) spec.paint_nozzle.enabled = values.Bool(named.Get("enabled"));
    } else if (type == "plugin_sensor") {
      spec.type = ObjectType::kDummy;
      spec.plugin_sensor = PluginSensor(named.Require("sensor"));
    } else {
      spec.type = ObjectType::kDummy;
    }
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

  // sensor: NAME of a sensor type a loaded plugin registers.
  std::string PluginSensor(const Field& field) {
    const std::string name = values.String(field);
    std::vector<std::string> known;
    if (registry != nullptr) {
      if (registry->FindPluginSensor(name) != nullptr) return name;
      for (const PluginSensorType& t : registry->plugin_sensors()) known.push_back(t.name);
    }
    if (known.empty())
      values.Fail(field, "unknown plugin sensor type '" + name +
                             "': no loaded plugin registers sensor types (plugins: [...])");
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    values.Fail(field, "unknown plugin sensor type '" + name + "' (registered: " + list + ")" +
                           Suggest(name, known));
  }

  ForceSensorData ForceSensor(const Fields& f) {
    ForceSensorData s;
    if (f.Has("filter_samples"))
      s.filter_samples = static_cast<int>(values.Integer(f.Get("filter_samples"), 1, 1000));
    if (f.Has("force_threshold"))
      s.force_threshold = values.Number(f.Get("force_threshold"), kPositive);
    if (f.Has("torque_threshold"))
      s.torque_threshold = values.Number(f.Get("torque_threshold"), kPositive);
    if (f.Has("break_after"))
      s.break_after = static_cast<int>(values.Integer(f.Get("break_after"), 1, 1000000));
    return s;
  }

  JointData Joint(const Fields& f) {
    JointData j;
    if (f.Has("joint")) {
      const std::string type =
          values.Choice(f.Get("joint"), {"revolute", "prismatic", "spherical", "fixed"});
      j.type = type == "revolute"    ? JointType::kRevolute
               : type == "prismatic" ? JointType::kPrismatic
               : type == "spherical" ? JointType::kSpherical
                                     : JointType::kFixed;
    }
    if (f.Has("mode")) {
      const std::string mode =
          values.Choice(f.Get("mode"), {"passive", "velocity", "position", "force"});
      j.mode = mode == "passive"    ? JointMode::kPassive
               : mode == "velocity" ? JointMode::kVelocity
               : mode == "position" ? JointMode::kPosition
                                    : JointMode::kForce;
    }
    if (f.Has("target_force")) j.target_force = values.Number(f.Get("target_force"), kAnyNumber);
    if (f.Has("limits")) {
      // [min, max] in rad or m, like initial_position.
      const Field limits = f.Get("limits");
      const std::vector<double> v = values.Numbers(limits, 2, 2, kAnyNumber);
      if (!(v[0] <= v[1])) values.Fail(limits, "'limits' must be [min, max] with min <= max");
      j.min_position = v[0];
      j.max_position = v[1];
    }
    if (f.Has("max_force")) j.max_force = values.Number(f.Get("max_force"), kPositive);
    if (f.Has("max_velocity")) j.max_velocity = values.Number(f.Get("max_velocity"), kPositive);
    if (f.Has("target_velocity"))
      j.target_velocity = values.Number(f.Get("target_velocity"), kAnyNumber);
    if (f.Has("target_position"))
      j.target_position = values.Number(f.Get("target_position"), kAnyNumber);
    if (f.Has("initial_position"))
      j.position = values.Number(f.Get("initial_position"), kAnyNumber);
    return j;
  }

  // `count` proximity sensors named `name` in a ring around the parent's z
  // axis: sensor i at angle start + 2 pi i / count counter-clockwise from the
  // parent's +x, its z axis (the ray) pointing radially outwards.
  void Ring(const Fields& f, const std::string& name, std::vector<ObjectSpec>* out) {
    const int64_t count = values.Integer(f.Require("count"), 1, kMaxRingCount);
    const double radius = values.Number(f.Require("radius"), kNonNegativeLength);
    const double height = f.Has("height") ? values.Number(f.Get("height"), kCoordinate) : 0.0;
    ProximitySensorData sensor;
    if (f.Has("range")) sensor.range = values.Number(f.Get("range"), kPositiveLength);
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
      spec.type = ObjectType::kProximitySensor;
      spec.sensor = sensor;
      spec.X_PO = {{radius * std::cos(theta), radius * std::sin(theta), height},
                   Quat::FromYaw(theta) * z_to_x};
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
  source->code = ReadFileOrThrow(path, "script file", where, text);
  sources_.emplace(key, source);
  return source;
}

// --- Shapes and poses ----------------------------------------------------------------

const std::vector<std::string>& ShapeKeys() {
  static const std::vector<std::string> keys = {"shape",   "size", "radius",   "height",
                                                "dynamic", "mass", "friction", "restitution",
                                                "color",   "file", "scale"};
  return keys;
}

const std::vector<std::string>& PoseKeys() {
  static const std::vector<std::string> keys = {"position", "orientation_deg", "heading_deg"};
  return keys;
}

ShapeData ReadShape(const ValueReader& values, const Fields& f, MeshCache* meshes) {
  ShapeData s;
  const std::string kind =
      values.Choice(f.Require("shape"), {"box", "cylinder", "sphere", "capsule", "mesh"});
  // Each kind takes its own size keys; a key of another kind is a mistake.
  auto forbid = [&](const char* key, const char* hint) {
    if (f.Has(key))
      values.file().Fail(f.Get(key).key_mark, "'" + std::string(key) + "' does not apply to a " +
                                                  kind + " (" + hint + ")");
  };
  if (kind != "mesh") {
    forbid("file", "only a mesh takes 'file: part.stl'");
    forbid("scale", "only a mesh takes 'scale: [sx, sy, sz]'");
  }
  if (kind == "mesh") {
    s.kind = ShapeKind::kMesh;
    for (const char* key : {"size", "radius", "height"})
      forbid(key, "a mesh takes 'file: part.stl|part.obj' and optionally 'scale: [sx, sy, sz]'");
    const Field file = f.Require("file");
    const std::string text = values.String(file);
    if (text.empty()) values.Fail(file, "'file' must be a mesh file name (.stl or .obj)");
    const Vec3 scale = f.Has("scale") ? values.Vector3(f.Get("scale"), kPositive) : Vec3{1, 1, 1};
    MeshCache local;
    if (!meshes) meshes = &local;
    s.mesh = meshes->Get(values.file().path().parent_path() / text, scale,
                         values.file().Where(file.mark), text);
    s.size = s.mesh->CenteredExtents();
  } else if (kind == "box") {
    s.kind = ShapeKind::kBox;
    forbid("radius", "a box takes 'size: [x, y, z]'");
    forbid("height", "a box takes 'size: [x, y, z]'");
    s.size = values.Vector3(f.Require("size"), kPositiveLength);
  } else if (kind == "cylinder" || kind == "capsule") {
    s.kind = kind == "cylinder" ? ShapeKind::kCylinder : ShapeKind::kCapsule;
    forbid("size", kind == "cylinder" ? "a cylinder takes 'radius' and 'height'"
                                      : "a capsule takes 'radius' and 'height' (caps included)");
    s.size = {values.Number(f.Require("radius"), kPositiveLength), 0,
              values.Number(f.Require("height"), kPositiveLength)};
    if (kind == "capsule" && s.size.z < 2 * s.size.x)
      values.Fail(f.Get("height"),
                  "a capsule's height includes its caps: it must be at least "
                  "twice its radius");
  } else {
    s.kind = ShapeKind::kSphere;
    forbid("size", "a sphere takes 'radius'");
    forbid("height", "a sphere takes 'radius'");
    s.size = {values.Number(f.Require("radius"), kPositiveLength), 0, 0};
  }
  if (f.Has("dynamic")) s.dynamic = values.Bool(f.Get("dynamic"));
  if (f.Has("mass")) s.mass = values.Number(f.Get("mass"), kPositive);
  if (f.Has("friction")) s.friction = values.Number(f.Get("friction"), kNonNegative);
  if (f.Has("restitution")) s.restitution = values.Number(f.Get("restitution"), kFraction);
  if (f.Has("color")) s.color = values.Vector3(f.Get("color"), kFraction);
  return s;
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

ModelFile ReadModelFile(YamlFile file, const std::string& used_by) {
  ModelFile model{std::move(file), {}, {}, {}, {}};
  const YamlFile& f = model.file;
  Field top{"model file", f.root(), f.root().Mark().is_null() ? YAML::Mark() : f.root().Mark(), {}};
  if (!f.root().IsMap())
    f.Fail(top.mark,
           "a model file must be a mapping with 'model', 'parameters' and 'objects' (got " +
               Describe(f.root()) + "; used by " + used_by + ")");
  Fields fields(f, top, "the model file");
  fields.Expect({"model", "description", "parameters", "objects", "ik_groups"});
  model.ik_groups = fields.Get("ik_groups");
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
  Builder builder{model, values, scripts, 0, meshes, registry};
  std::vector<ObjectSpec> out;
  builder.Object(model.root, 0, true, &out);
  return std::move(out.front());
}

// --- Scene ----------------------------------------------------------------------------

ObjectId AddToScene(const ObjectSpec& spec, ObjectId parent, Scene* scene) {
  ObjectId id;
  switch (spec.type) {
    case ObjectType::kShape: id = scene->AddShape(spec.name, parent, spec.X_PO, spec.shape); break;
    case ObjectType::kJoint: id = scene->AddJoint(spec.name, parent, spec.X_PO, spec.joint); break;
    case ObjectType::kProximitySensor:
      id = scene->AddProximitySensor(spec.name, parent, spec.X_PO, spec.sensor);
      break;
    case ObjectType::kForceSensor:
      id = scene->AddForceSensor(spec.name, parent, spec.X_PO, spec.force_sensor);
      break;
    case ObjectType::kPaintNozzle:
      id = scene->AddPaintNozzle(spec.name, parent, spec.X_PO, spec.paint_nozzle);
      break;
    case ObjectType::kDummy: id = scene->AddDummy(spec.name, parent, spec.X_PO); break;
  }
  if (!spec.plugin_sensor.empty()) scene->WriteCustomData(id, kPluginSensorTag, spec.plugin_sensor);
  if (spec.script) scene->AttachScript(id, spec.script, spec.script_explicit);
  for (const ObjectSpec& child : spec.children) AddToScene(child, id, scene);
  return id;
}

namespace {

void Accumulate(const ObjectSpec& spec, const Pose& X_RP, Footprint* fp, bool* any) {
  const Pose X_RO = X_RP * spec.X_PO;
  if (spec.type == ObjectType::kShape) {
    const ShapeData& s = spec.shape;
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
    double bottom = X_RO.p.z - e.z;
    if (s.kind == ShapeKind::kMesh && s.mesh) {  // exact over its vertices
      radius = 0;
      bottom = std::numeric_limits<double>::infinity();
      for (const Vec3& v : s.mesh->vertices()) {
        const Vec3 p = X_RO * v;
        radius = std::max(radius, std::hypot(p.x, p.y));
        bottom = std::min(bottom, p.z);
      }
    }
    if (!*any) {
      fp->radius = radius;
      fp->bottom = bottom;
      *any = true;
    } else {
      fp->radius = std::max(fp->radius, radius);
      fp->bottom = std::min(fp->bottom, bottom);
    }
  }
  const Pose X_RC = spec.type == ObjectType::kJoint ? X_RO * spec.joint.Motion() : X_RO;
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
