// WorldLoader: the `models:` entries of a world file. Each entry is resolved
// (its model's parameters, its copies' own values, its objects, its
// placement), then the entries are placed together and their copies built.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <tuple>
#include <utility>

#include "framework/error.h"
#include "framework/memory_forecast.h"
#include "framework/model_section.h"
#include "framework/object_type.h"
#include "framework/plugin_controllers.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "swarm/loader/object_reader.h"
#include "swarm/loader/urdf.h"
#include "swarm/loader/world_loader_impl.h"

namespace swarmsim::loader {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

// A parameter value outside its declared range: the message, or "".
std::string RangeError(const loader::ModelParameterDecl& decl, const std::string& model,
                       const ParamValue& value) {
  if (!decl.has_range) return "";
  const double* v = std::get_if<double>(&value);
  if (v != nullptr && *v >= decl.min && *v <= decl.max) return "";
  // A unit is shown unless it is the dimensionless "1" ("within [0, 1] 1" reads as a typo).
  const std::string range = "[" + loader::FormatNumber(decl.min) + ", " +
                            loader::FormatNumber(decl.max) + "]" +
                            (decl.unit.empty() || decl.unit == "1" ? "" : " " + decl.unit);
  const std::string what = "parameter '" + decl.name + "' of model '" + model + "'";
  if (v == nullptr)  // a string or a boolean: the range makes it a number parameter
    return what + " must be a number within " + range + " (got " +
           (std::holds_alternative<std::string>(value) ? "\"" + ShowParamValue(value) + "\""
                                                       : ShowParamValue(value)) +
           ", which is not a number)";
  return what + " must be within " + range + " (got " + ShowParamValue(value) + ")";
}

// A models entry's `joints:` (an imported robot's joints, which a URDF
// cannot set): limit_erp, limit_cfm for joints without their own (negative:
// none); `mode` for every joint that follows no master; `limits: false`
// frees every joint's limits.
struct EntryJoints {
  double limit_erp = -1, limit_cfm = -1;
  std::optional<JointMode> mode;
  bool free_limits = false;
  std::map<std::string, double> positions;  // `positions`: joint name -> where it starts
};

// The joints of `spec` and below, by name.
void FindJoints(const ObjectSpec& spec, std::map<std::string, const JointData*>* out) {
  if (const JointData* joint = spec.As<JointData>(ObjectType::kJoint)) (*out)[spec.name] = joint;
  for (const ObjectSpec& child : spec.children) FindJoints(child, out);
}

// `joints` on every joint of `spec`, each changed one in a row of its own
// (rows may be shared with other entries).
void SetEntryJoints(const EntryJoints& joints, ObjectSpec* spec) {
  if (const JointData* joint = spec->As<JointData>(ObjectType::kJoint)) {
    const bool erp = joints.limit_erp >= 0 && joint->settings->limit_erp < 0;
    const bool cfm = joints.limit_cfm >= 0 && joint->settings->limit_cfm < 0;
    const bool mode =
        joints.mode && joint->settings->depends == nullptr && joint->settings->mode != *joints.mode;
    const bool free = joints.free_limits && (std::isfinite(joint->settings->min_position) ||
                                             std::isfinite(joint->settings->max_position));
    const auto position = joints.positions.find(spec->name);
    if (erp || cfm || mode || free || position != joints.positions.end()) {
      const ObjectTypeDescriptor& type =
          *CoreObjectTypes()[static_cast<size_t>(ObjectType::kJoint)];
      std::shared_ptr<RowTable> row = type.make_rows(type);
      row->Append(joint, 0);
      JointData& copy = *static_cast<JointData*>(row->At(0));
      JointSettings& settings = copy.settings.Edit();
      if (erp) settings.limit_erp = joints.limit_erp;
      if (cfm) settings.limit_cfm = joints.limit_cfm;
      if (mode) settings.mode = *joints.mode;
      if (free) settings.min_position = -INFINITY, settings.max_position = INFINITY;
      if (position != joints.positions.end()) copy.JumpTo(position->second);  // and held there
      spec->row = std::move(row);
    }
  }
  for (ObjectSpec& child : spec->children) SetEntryJoints(joints, &child);
}

// `show_collision: true`: every hidden shape named `collision` below `spec`
// (an imported link's collision geometry) drawn, in a row of its own.
void ShowCollisionShapes(ObjectSpec* spec) {
  const auto* shape = spec->As<Shared<ShapeData>>(ObjectType::kShape);
  if (shape != nullptr && spec->name == "collision" && !(*shape)->visible) {
    const ObjectTypeDescriptor& type = *CoreObjectTypes()[static_cast<size_t>(ObjectType::kShape)];
    std::shared_ptr<RowTable> row = type.make_rows(type);
    row->Append(shape, 0);
    static_cast<Shared<ShapeData>*>(row->At(0))->Edit().visible = true;
    spec->row = std::move(row);
  }
  for (ObjectSpec& child : spec->children) ShowCollisionShapes(&child);
}
}  // namespace

// --- Resolving an entry ----------------------------------------------------------------

std::vector<std::string> ModelSectionKeys(const ModuleRegistry& registry) {
  std::vector<std::string> keys;
  for (const auto& section : registry.model_sections()) keys.push_back(section->key);
  return keys;
}

std::vector<std::string> EntryKeys(const ModuleRegistry& registry) {
  std::vector<std::string> keys = {
      "model",           "count",      "distribute", "position", "heading_deg",
      "orientation_deg", "parameters", "instances",  "scale",    "base",
      "show_collision",  "objects",    "scripts",    "joints"};
  for (std::string& key : ModelSectionKeys(registry)) keys.push_back(std::move(key));
  keys.insert(keys.end(), {"python_controller", "native_controller"});
  return keys;
}

std::vector<std::shared_ptr<const ModelSectionData>> ReadModelSections(
    const ModuleRegistry& registry, const ObjectReader& top, const std::string& model) {
  std::vector<std::shared_ptr<const ModelSectionData>> out;
  for (const auto& section : registry.model_sections()) out.push_back(section->read(top, model));
  return out;
}

namespace {
void DropScripts(ObjectSpec* spec);
}  // namespace

void WorldLoader::ResolveEntry(EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  const ValueReader world_values = WorldValues();
  Fields f(*file_, entry->field, "the models entry for '" + model.name + "'");
  f.Expect(EntryKeys(registry_));
  DeclaredParameters declared;
  ResolveEntryParameters(f, world_values, &declared, entry);
  ReadOwnCopies(f, world_values, &declared, entry);
  ResolveObjects(f, world_values, entry);
  ResolvePlacement(f, world_values, entry);
  ResolveNativeController(f, world_values, entry);
  ResolvePythonController(f, world_values, entry);
  // Models Python drives without their Lua scripts (World(..., keep_scripts=False)).
  if (std::find(options_.drop_scripts.begin(), options_.drop_scripts.end(), model.name) !=
      options_.drop_scripts.end()) {
    DropScripts(&entry->spec);
    for (EntryPlan::OwnCopy& own : entry->own_copies)
      if (own.spec) DropScripts(&*own.spec);
  }
}

namespace {
bool HasScripts(const ObjectSpec& spec) {
  if (spec.script) return true;
  for (const ObjectSpec& child : spec.children)
    if (HasScripts(child)) return true;
  return false;
}

void DropScripts(ObjectSpec* spec) {
  spec->script = nullptr;
  spec->script_explicit = false;
  for (ObjectSpec& child : spec->children) DropScripts(&child);
}
}  // namespace

// The planar engines roll a wheel that is a non-dynamic cylinder or sphere
// under a velocity-mode revolute joint (modules/dynamics/plane_wheels.h); an
// imported robot's wheel links are bodies of their own, which they do not
// roll: a floating TurtleBot under box2d turned its wheels and stood still,
// with no word.
void WorldLoader::AddPlaneWheelHints(const WorldSettings& settings,
                                     std::vector<std::string>* warnings) const {
  if (settings.physics != "box2d" && settings.physics != "planar") return;
  for (const EntryPlan& e : entries_) {
    if (!e.model->imported) continue;
    std::vector<std::string> joints;
    std::function<void(const ObjectSpec&)> walk = [&](const ObjectSpec& o) {
      if (const auto* joint = o.As<JointData>(ObjectType::kJoint);
          joint != nullptr && joint->type() == JointType::kRevolute &&
          joint->mode() == JointMode::kVelocity)
        for (const ObjectSpec& c : o.children)
          if (const ShapeData* shape = c.AsShape(); shape != nullptr && shape->dynamic) {
            joints.push_back(o.name);
            break;
          }
      for (const ObjectSpec& c : o.children) walk(c);
    };
    walk(e.spec);
    if (joints.empty()) continue;
    std::string list;
    for (size_t i = 0; i < joints.size() && i < 3; ++i) list += (i ? ", " : "") + joints[i];
    if (joints.size() > 3) list += ", ...";
    warnings->push_back(file_->Where(e.field.mark) + ": '" + e.model->name + "' drives " +
                        std::to_string(joints.size()) + " joint" + (joints.size() == 1 ? "" : "s") +
                        " (" + list +
                        ") whose links are bodies of their own, not the wheels that " +
                        "physics: " + settings.physics +
                        " rolls (a non-dynamic cylinder or sphere under the joint): it will not "
                        "move; use physics: ode, where they roll as bodies");
  }
}

// From this many robots, the defaults below cost enough to say so (README,
// "Performance": at 100,000 robots a state each takes twice the memory of
// 64 robots a state, and random numbering 1.3x the time a step).
constexpr int64_t kLargeSwarm = 10000;

void WorldLoader::AddLargeSwarmHints(const WorldSettings& settings,
                                     std::vector<std::string>* warnings) const {
  int64_t lua_robots = 0, robots = 0;
  for (const EntryPlan& e : entries_) {
    robots += e.count;
    if (HasScripts(e.spec) && !(e.native != nullptr && e.native_replaces_scripts))
      lua_robots += e.count;
    if (!e.distribute || e.lattice || e.order_given || e.count < kLargeSwarm ||
        !e.own_copies.empty())
      continue;
    warnings->push_back(file_->Where(e.count_field.mark) + ": " + GroupThousands(e.count) +
                        " copies of '" + e.model->name +
                        "' numbered in the order they were drawn; with 'distribute: {order: "
                        "spatial}' they are numbered along a curve, so that neighbours lie near "
                        "each other in memory and a step takes less time, unless the "
                        "controller gives robots roles by their number (worlds/README.md, "
                        "\"Placement\"; 'order: random' keeps this order without this note)");
  }
  if (settings.physics == "box2d" && robots >= kLargeSwarm && !physics_partitions_given_)
    warnings->push_back(file_->name() + ": " + GroupThousands(robots) +
                        " robots under physics: box2d in one world; with 'simulation: "
                        "{physics_partitions: auto}' regions of the arena are stepped on every "
                        "thread (a model setting: it changes results, never with the thread "
                        "count; worlds/README.md, \"Physics partitions\"; "
                        "'physics_partitions: 1' keeps one world without this note)");
  if (lua_robots < kLargeSwarm || robots_per_lua_state_given_ || settings.trust_scripts) return;
  warnings->push_back(file_->name() + ": " + GroupThousands(lua_robots) +
                      " robots run Lua scripts, a Lua state each; with 'simulation: "
                      "{robots_per_lua_state: 64}' 64 robots share a state, each with its own "
                      "globals, in less memory and time (a foot-bot's Lua: about 4 KiB instead "
                      "of 17; worlds/README.md, \"Robots sharing a Lua state\"; "
                      "'robots_per_lua_state: 1' keeps a state each without this note)");
}

// python_controller: FILE.py, FILE.py:function, or {file, function, keep_scripts}.
void WorldLoader::ResolvePythonController(const Fields& f, const ValueReader& world_values,
                                          EntryPlan* entry) {
  if (!f.Has("python_controller")) return;
  Field file_field = f.Get("python_controller");
  PythonController& python = entry->python;
  python.where = file_->Where(file_field.key_mark);
  if (file_field.node.IsMap()) {
    Fields p(*file_, file_field, "'python_controller'");
    p.Expect({"file", "function", "keep_scripts"});
    if (p.Has("function")) python.function = world_values.String(p.Get("function"));
    if (p.Has("keep_scripts")) python.keep_scripts = world_values.Bool(p.Get("keep_scripts"));
    file_field = p.Require("file");
  }
  std::string text = world_values.String(file_field);
  const std::string written = text;  // as the file says it, for messages
  if (!file_field.node.IsMap()) {
    const size_t colon = text.rfind(':');
    if (colon != std::string::npos && colon > 0) {
      python.function = text.substr(colon + 1);
      text.resize(colon);
    }
  }
  const auto identifier = [](const std::string& name) {
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
  };
  if (!identifier(python.function))
    file_->Fail(file_field.mark, "'python_controller' names a Python function: '" +
                                     python.function + "' is not an identifier");
  if (text.size() < 4 || text.substr(text.size() - 3) != ".py")
    file_->Fail(file_field.mark,
                "'python_controller' is a Python file (FILE.py or FILE.py:function), got '" +
                    written + "'");
  const std::filesystem::path path = file_->path().parent_path() / text;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    file_->Fail(file_field.mark, "'python_controller': no file " + path.string());
  python.file = std::filesystem::absolute(path, ec).lexically_normal();
  if (!options_.python_controllers)
    file_->Fail(f.Get("python_controller").key_mark,
                "model '" + entry->model->name +
                    "' has a Python controller: run this world from Python "
                    "(PYTHONPATH=build/python /usr/bin/python3 -m swarmsim run " +
                    path_.string() + ", README.md 'Python')");
  if (!python.keep_scripts) {
    DropScripts(&entry->spec);
    for (EntryPlan::OwnCopy& own : entry->own_copies)
      if (own.spec) DropScripts(&*own.spec);
  }
}

// native_controller: NAME, or {name: NAME, keep_scripts: true}: a controller
// a plugin of the world's `plugins:` registered (add_controller).
void WorldLoader::ResolveNativeController(const Fields& f, const ValueReader& world_values,
                                          EntryPlan* entry) {
  if (!f.Has("native_controller")) return;
  Field name_field = f.Get("native_controller");
  bool keep_scripts = false;
  if (name_field.node.IsMap()) {
    Fields n(*file_, name_field, "'native_controller'");
    n.Expect({"name", "keep_scripts"});
    if (n.Has("keep_scripts")) keep_scripts = world_values.Bool(n.Get("keep_scripts"));
    name_field = n.Require("name");
  }
  if (f.Has("python_controller"))
    file_->Fail(f.Get("native_controller").key_mark,
                "a models entry has either a 'python_controller' or a 'native_controller', "
                "not both");
  const std::string name = world_values.String(name_field);
  entry->native = world_registry_->FindController(name);
  if (entry->native == nullptr) {
    const std::vector<std::string> known = world_registry_->ControllerNames();
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    file_->Fail(
        name_field.mark,
        "'native_controller': no controller '" + name + "' (" +
            (known.empty() ? std::string("no plugin of the world's 'plugins:' registers "
                                         "one: list the plugin that has it there, as "
                                         "'plugins: [diffusion_controller]' for swarmsim's C++ "
                                         "diffusion controller")
                           : "registered: " + list) +
            ")" + [&]() -> std::string {  // the list is there: only a near name
          const std::string* near = NearestName(name, known);
          return near != nullptr ? "; did you mean '" + *near + "'?" : "";
        }());
  }
  if (!keep_scripts) {
    entry->native_replaces_scripts = HasScripts(entry->spec);
    DropScripts(&entry->spec);
    for (EntryPlan::OwnCopy& own : entry->own_copies)
      if (own.spec) DropScripts(&*own.spec);
  }
}

// Model parameters: declared defaults, then this entry's values, then --set.
void WorldLoader::ResolveEntryParameters(const Fields& f, const ValueReader& world_values,
                                         DeclaredParameters* declared, EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  for (const auto& decl : model.parameters) {
    declared->where[decl.name] = model.file.Where(decl.default_value.mark);
    declared->names.push_back(decl.name);
  }
  const Field none;
  entry->parameters = ModelParameters(model, f.Has("parameters") ? f.Get("parameters") : none, none,
                                      world_values, *declared);
}

// One copy's values, in the model's declaration order: the default (which
// may use the world's parameters and the model's above it, with the values
// this copy ends with), then the entry's value, then the copy's own
// (`instances`), then --set.
std::shared_ptr<ParameterSet> WorldLoader::ModelParameters(const ModelFile& model,
                                                           const Field& entry_values,
                                                           const Field& own_values,
                                                           const ValueReader& world_values,
                                                           const DeclaredParameters& declared) {
  const std::vector<std::string>& names = declared.names;
  std::vector<Fields> layers;
  for (const Field* given : {&entry_values, &own_values}) {
    if (!given->present()) continue;
    layers.emplace_back(*file_, *given, "the parameters of model '" + model.name + "'");
    for (const Field& p : layers.back().fields())
      if (!declared.where.contains(p.name))
        file_->Fail(p.key_mark,
                    "model '" + model.name + "' has no parameter '" + p.name + "'" +
                        (names.empty() ? " (it declares none)" : loader::Suggest(p.name, names)));
  }
  auto params = std::make_shared<ParameterSet>();
  loader::ParametersBeingRead reading;
  for (const auto& decl : model.parameters)
    reading.later.emplace(decl.name, "line " + std::to_string(decl.mark.line + 1));
  for (const auto& decl : model.parameters) {
    reading.current = decl.name;
    reading.later.erase(decl.name);
    const ValueReader defaults(model.file, &expressions_, {&parameters_, params.get(), &reading});
    ParamValue value = defaults.Resolve(decl.default_value);
    if (std::string e = RangeError(decl, model.name, value); !e.empty())
      model.file.Fail(decl.default_value.mark, "the default of " + e);
    for (const Fields& layer : layers) {
      if (!layer.Has(decl.name)) continue;
      const Field p = layer.Get(decl.name);
      const ParamValue given = world_values.Resolve(p);
      if (given.index() != value.index() && !std::holds_alternative<std::string>(value))
        file_->Fail(p.mark, "parameter '" + p.name + "' of model '" + model.name + "' is " +
                                loader::TypeName(value) + " (" + declared.where.at(p.name) +
                                "), got " + loader::Describe(p.node));
      value = std::holds_alternative<std::string>(value) ? ParamValue(ParamToString(given)) : given;
      if (std::string e = RangeError(decl, model.name, value); !e.empty()) file_->Fail(p.mark, e);
    }
    for (Override& o : overrides_) {
      if (o.model != model.name || o.name != decl.name) continue;
      value = CoerceOverride(o, value, declared.where.at(o.name));
      if (std::string e = RangeError(decl, model.name, value); !e.empty())
        throw Error(o.text + ": " + e + " (declared at " + declared.where.at(o.name) + ")");
    }
    (*params)[decl.name] = std::move(value);
  }
  return params;
}

// instances: copies with their own values: over the entry's, before --set
// (which sets every copy of the model).
void WorldLoader::ReadOwnCopies(const Fields& f, const ValueReader& world_values,
                                DeclaredParameters* declared, EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  for (const Field& element : loader::ListElements(*file_, f.Get("instances"), "instances")) {
    Fields inst(*file_, element, "an instances entry");
    inst.Expect({"index", "parameters"});
    const int64_t index = world_values.Integer(inst.Require("index"), 0, kMaxCount - 1);
    if (entry->own_copy_of.contains(index))
      file_->Fail(inst.Get("index").mark,
                  "copy " + std::to_string(index) + " is given twice in 'instances'");
    const Field none;
    auto own = ModelParameters(model, f.Has("parameters") ? f.Get("parameters") : none,
                               inst.Require("parameters"), world_values, *declared);
    entry->own_copy_of.emplace(index, entry->own_copies.size());
    entry->own_copies.push_back({index, element, std::move(own), std::nullopt, {}, {}});
  }
}

// The model's objects, in a scope where its parameters shadow the world's;
// its scale and IK groups; the objects of the copies with values of their own.
void WorldLoader::ResolveObjects(const Fields& f, const ValueReader& world_values,
                                 EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  const std::shared_ptr<ParameterSet>& params = entry->parameters;
  const ValueReader model_values(model.file, &expressions_, {&parameters_, params.get()});
  try {
    entry->spec = loader::ResolveModel(model, model_values, &scripts_, &meshes_, world_registry_);
  } catch (const Error& e) {
    // A value of the model file may be the entry's (`script: $controller`
    // with `parameters: {controller: ...}`): the message names the model
    // file's line, which the user did not write.
    if (!f.Has("parameters")) throw;
    throw Error(std::string(e.what()) + " (with the parameters of the models entry given at " +
                file_->Where(f.Get("parameters").mark) + ")");
  }
  ExtendObjects(f, world_values, *entry, &entry->spec);
  entry->footprint = loader::ComputeFootprint(entry->spec);
  if (f.Has("scale")) {
    // Every length of the model scales, so its footprint does too.
    static constexpr NumberRule kScale{"a number from 0.001 to 1000", 1e-3, 1e3};
    entry->scale = world_values.Number(f.Get("scale"), kScale);
    entry->footprint.radius *= entry->scale;
    entry->footprint.bottom *= entry->scale;
    entry->footprint.top *= entry->scale;
  }
  // The model file's sections (IK groups), and the entry's own keys of the
  // same name (an imported robot's): paths and messages in the world file.
  const auto read_sections = [&](const ValueReader& values) {
    if (!model.top.present())  // an imported model: only the entry's own keys
      return std::vector<std::shared_ptr<const ModelSectionData>>(
          registry_.model_sections().size());
    const Fields top(model.file, model.top, "the model file");
    return ReadModelSections(registry_, FieldsObjectReader(values, top, &meshes_, world_registry_),
                             model.name);
  };
  entry->sections = read_sections(model_values);
  entry->entry_sections = ReadModelSections(
      registry_, FieldsObjectReader(world_values, f, &meshes_, world_registry_), model.name);
  // A copy with values of its own gets objects of its own: every value of
  // the model that uses a parameter (a sensor's range, a size, a limit, a
  // mass, an IK setting) takes the copy's value.
  for (EntryPlan::OwnCopy& own : entry->own_copies) {
    if (*own.parameters == *params) continue;  // nothing of its own: duplicated as the others
    const ValueReader own_values(model.file, &expressions_, {&parameters_, own.parameters.get()});
    try {
      own.spec = loader::ResolveModel(model, own_values, &scripts_, &meshes_, world_registry_);
      ExtendObjects(f, world_values, *entry, &*own.spec);
      own.sections = read_sections(own_values);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (with the parameters of copy " +
                  std::to_string(own.index) + " given at " + file_->Where(own.field.mark) + ")");
    }
    own.footprint = loader::ComputeFootprint(*own.spec);
    own.footprint.radius *= entry->scale;
    own.footprint.bottom *= entry->scale;
    own.footprint.top *= entry->scale;
  }
}

// What the entry adds to its model's objects: `base: floating` (URDF), the
// `objects` under the root (IK targets, sensors) and `scripts` attached to
// the root or to a named object (an imported robot's link).
void WorldLoader::ExtendObjects(const Fields& f, const ValueReader& world_values,
                                const EntryPlan& entry, ObjectSpec* spec) {
  const ModelFile& model = *entry.model;
  if (f.Has("base")) {
    const Field base = f.Get("base");
    const std::string kind = world_values.Choice(base, {"fixed", "floating"});
    if (!model.imported)
      world_values.Fail(base,
                        "'base' applies to URDF models (a model file says which shapes "
                        "are dynamic itself)");
    if (kind == "floating") *spec = loader::WithFloatingBase(*spec, file_->Where(base.mark));
  }
  if (f.Has("show_collision")) {
    const Field show = f.Get("show_collision");
    if (!model.imported)
      world_values.Fail(show,
                        "'show_collision' applies to URDF models (a model file says which "
                        "shapes are visible itself)");
    if (world_values.Bool(show)) ShowCollisionShapes(spec);
  }
  if (f.Has("joints")) {
    // Joint settings for every joint of the model without its own (ode).
    Fields joints(*file_, f.Get("joints"), "'joints'");
    joints.Expect({"limit_erp", "limit_cfm", "mode", "limits", "positions"});
    EntryJoints settings;
    if (joints.Has("limit_erp"))
      settings.limit_erp = world_values.Number(joints.Get("limit_erp"), kFraction);
    if (joints.Has("limit_cfm"))
      settings.limit_cfm = world_values.Number(joints.Get("limit_cfm"), kFraction);
    if (joints.Has("mode")) {
      const std::string mode =
          world_values.Choice(joints.Get("mode"), {"passive", "velocity", "position", "force"});
      settings.mode = mode == "passive"    ? JointMode::kPassive
                      : mode == "velocity" ? JointMode::kVelocity
                      : mode == "position" ? JointMode::kPosition
                                           : JointMode::kForce;
    }
    if (joints.Has("limits")) {
      const Field limits = joints.Get("limits");
      if (world_values.Bool(limits))
        file_->Fail(limits.mark,
                    "'limits' takes false (free every joint's limits); a joint's "
                    "own limits are its own");
      settings.free_limits = true;
    }
    if (joints.Has("positions")) {
      // Where named joints start (rad or m), within their limits: an
      // imported arm's ready pose (a URDF has none).
      std::map<std::string, const JointData*> known;
      FindJoints(*spec, &known);
      std::vector<std::string> names;
      for (const auto& [name, joint] : known) names.push_back(name);
      Fields positions(*file_, joints.Get("positions"), "'positions'");
      for (const Field& p : positions.fields()) {
        const auto joint = known.find(p.name);
        if (const auto merged = model.merged_joints.find(p.name);
            joint == known.end() && merged != model.merged_joints.end())
          file_->Fail(p.key_mark,
                      "joint '" + p.name + "' of '" + model.imported_file + "' is a " +
                          merged->second + " joint: it has no position (" +
                          (merged->second == "floating" ? "its child link is a free body"
                                                        : "its links are merged into one body") +
                          "); positions are for moving joints");
        if (joint == known.end())
          file_->Fail(p.key_mark,
                      "model '" + model.name + "' has no joint '" + p.name + "'" +
                          (names.empty() ? " (it has none)" : loader::Suggest(p.name, names)));
        const double q = world_values.Number(p, kAnyNumber);
        const JointSettings& s = *joint->second->settings;
        if (s.depends != nullptr)
          file_->Fail(p.key_mark, "joint '" + p.name + "' follows '" + s.depends->master +
                                      "' (a mimic or dependent joint): give that joint's "
                                      "position, and this one starts where it puts it");
        if (!(std::abs(q) <= 1e6))
          file_->Fail(p.mark, "joint '" + p.name + "' starts at " + loader::FormatNumber(q) +
                                  ", beyond the 1e6 (m or rad) a world may use");
        if (!settings.free_limits && !(q >= s.min_position && q <= s.max_position))
          file_->Fail(p.mark, "joint '" + p.name + "' starts at " + loader::FormatNumber(q) +
                                  ", outside its limits [" + loader::FormatNumber(s.min_position) +
                                  ", " + loader::FormatNumber(s.max_position) + "]");
        settings.positions[p.name] = q;
      }
    }
    SetEntryJoints(settings, spec);
  }
  if (f.Has("objects")) {
    std::vector<ObjectSpec> extra = loader::ReadSceneObjects(*file_, f.Get("objects"), world_values,
                                                             &scripts_, &meshes_, world_registry_);
    for (ObjectSpec& o : extra) spec->children.push_back(std::move(o));
  }
  if (f.Has("scripts")) {
    Fields scripts(*file_, f.Get("scripts"), "'scripts'");
    std::map<const ObjectSpec*, std::string> given;  // object -> the key that gave its script
    for (const Field& s : scripts.fields()) {
      // ':' (or '.') the root; else the first object of that name, in hierarchy order.
      ObjectSpec* target = nullptr;
      std::vector<std::string> names;
      std::vector<ObjectSpec*> stack{spec};
      while (!stack.empty() && target == nullptr) {
        ObjectSpec* at = stack.back();
        stack.pop_back();
        names.push_back(at->name);
        if (at != spec && at->name == s.name) target = at;
        for (auto it = at->children.rbegin(); it != at->children.rend(); ++it)
          stack.push_back(&*it);
      }
      if (s.name == ":" || s.name == "." || (target == nullptr && s.name == spec->name))
        target = spec;
      if (target == nullptr)
        file_->Fail(s.key_mark, "no object '" + s.name + "' in model '" + model.name +
                                    "' to attach a script to (':' is the root)" +
                                    loader::Suggest(s.name, names));
      if (const auto [it, added] = given.emplace(target, s.name); !added)
        file_->Fail(s.key_mark, "'" + s.name + "' and '" + it->second +
                                    "' name the same object of model '" + model.name +
                                    "' (an object runs one script: give it one)");
      const std::string text = world_values.String(s);
      if (text.empty()) world_values.Fail(s, "a script must be a file name");
      target->script = scripts_.Get(path_.parent_path() / text, file_->Where(s.mark), text);
    }
  }
}

// Placement: distributed copies or one placed copy; then the copies given
// values of their own must be among them.
void WorldLoader::ResolvePlacement(const Fields& f, const ValueReader& world_values,
                                   EntryPlan* entry) {
  if (f.Has("distribute"))
    ReadDistribution(f, world_values, entry);
  else
    ReadSinglePosition(f, world_values, entry);
  for (const EntryPlan::OwnCopy& own : entry->own_copies)
    if (own.index >= entry->count)
      file_->Fail(Fields(*file_, own.field, "an instances entry").Get("index").mark,
                  "'index' must be below the entry's count (" + std::to_string(entry->count) +
                      "): copies are numbered from 0");
}

// distribute: `count` copies spread over a region.
void WorldLoader::ReadDistribution(const Fields& f, const ValueReader& world_values,
                                   EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  for (const char* key : {"position", "heading_deg", "orientation_deg"})
    if (f.Has(key))
      file_->Fail(f.Get(key).key_mark,
                  "'" + std::string(key) +
                      "' places a single copy; it cannot be combined with "
                      "'distribute' (use distribute.heading_deg for a fixed heading)");
  entry->distribute = true;
  entry->count_field = f.Require("count");
  entry->count = world_values.Integer(entry->count_field, 0, INT64_MAX / 2,
                                      "a whole number from 0 to 1,000,000");
  if (entry->count > kMaxCount)
    file_->Fail(entry->count_field.mark,
                "'count' is at most 1,000,000 copies a models entry (got " +
                    std::to_string(entry->count) +
                    "): give a larger swarm as several entries of the model, each with its own "
                    "count and region");
  Fields d(*file_, f.Get("distribute"), "'distribute'");
  d.Expect({"region", "clearance", "heading_deg", "order", "lattice"});
  const Field region = d.Get("region");
  if (!region.present() || (region.node.IsScalar() && world_values.String(region) == "arena")) {
    if (!arena_)
      file_->Fail(region.present() ? region.mark : d.mark(),
                  "distributing in the arena needs an 'arena' in the world; or give "
                  "'region: {min: [x, y], max: [x, y]}'");
    entry->region = *arena_;
    entry->region_text = "the arena";
  } else if (region.node.IsMap()) {
    Fields r(*file_, region, "'region'");
    r.Expect({"min", "max"});
    const std::vector<double> lo = world_values.Numbers(r.Require("min"), 2, 2, kCoordinate);
    const std::vector<double> hi = world_values.Numbers(r.Require("max"), 2, 2, kCoordinate);
    if (!(lo[0] < hi[0] && lo[1] < hi[1]))
      file_->Fail(r.Get("max").mark, "'region' needs max greater than min in x and in y");
    entry->region = {lo[0], lo[1], hi[0], hi[1]};
    entry->region_field = region;
    using loader::FormatNumber;
    entry->region_text = "the region from [" + FormatNumber(lo[0]) + ", " + FormatNumber(lo[1]) +
                         "] to [" + FormatNumber(hi[0]) + ", " + FormatNumber(hi[1]) + "]";
  } else {
    file_->Fail(region.mark, "'region' must be 'arena' or {min: [x, y], max: [x, y]} (got " +
                                 loader::Describe(region.node) + ")");
  }
  if (d.Has("clearance"))
    entry->clearance = world_values.Number(d.Get("clearance"), kNonNegativeLength);
  if (d.Has("heading_deg"))
    entry->heading = world_values.Number(d.Get("heading_deg"), kAngleDeg) * kDegToRad;
  if (d.Has("order")) {
    const Field order = d.Get("order");
    const std::string text = world_values.String(order);
    if (text != "random" && text != "spatial")
      file_->Fail(order.mark, "'order' must be random or spatial (got '" + text + "')");
    entry->spatial_order = text == "spatial";
    entry->order_given = true;
    if (d.Has("lattice"))
      file_->Fail(order.key_mark,
                  "'order' is for random placement; a lattice numbers its "
                  "copies row by row");
    if (entry->spatial_order && !entry->own_copies.empty())
      file_->Fail(order.mark,
                  "'order: spatial' renumbers the copies by where they stand, "
                  "and 'instances' gives values to copies by number: use one "
                  "or the other");
  }
  const double r = entry->MaxFootprintRadius();
  if (d.Has("lattice")) ReadLattice(d, world_values, r, entry);
  if (entry->count > 0 && (entry->region.max_x - entry->region.min_x < 2 * r ||
                           entry->region.max_y - entry->region.min_y < 2 * r))
    file_->Fail(entry->count_field.mark, "the region is too small for one " + model.name +
                                             " (footprint radius " + loader::FormatNumber(r) +
                                             " m)");
}

// distribute.lattice: {spacing, shape: square | hexagonal, columns}.
void WorldLoader::ReadLattice(const Fields& d, const ValueReader& world_values,
                              double footprint_radius, EntryPlan* entry) {
  if (d.Has("clearance"))
    file_->Fail(d.Get("clearance").key_mark,
                "'clearance' is for random placement; a lattice's 'spacing' sets the gap");
  const Field field = d.Get("lattice");
  Fields l(*file_, field, "'lattice'");
  l.Expect({"spacing", "shape", "columns"});
  EntryPlan::LatticePlan plan;
  plan.field = field;
  const Field spacing = l.Require("spacing");
  plan.spacing = world_values.Number(spacing, kPositiveLength);
  if (plan.spacing < 2 * footprint_radius)
    file_->Fail(spacing.mark, "a lattice 'spacing' of " + loader::FormatNumber(plan.spacing) +
                                  " m is less than the footprint diameter of the " +
                                  entry->model->name + " model (" +
                                  loader::FormatNumber(2 * footprint_radius) +
                                  " m): neighbouring copies would overlap");
  if (l.Has("shape")) {
    const std::string shape = world_values.String(l.Get("shape"));
    if (shape != "square" && shape != "hexagonal")
      file_->Fail(l.Get("shape").mark, "'shape' must be square or hexagonal (got '" + shape + "')");
    plan.hexagonal = shape == "hexagonal";
  }
  const int64_t square_side = static_cast<int64_t>(
      std::ceil(std::sqrt(static_cast<double>(std::max<int64_t>(entry->count, 1)))));
  plan.columns =
      l.Has("columns") ? world_values.Integer(l.Get("columns"), 1, kMaxCount) : square_side;
  entry->lattice = plan;
}

// position: one copy at a fixed pose.
void WorldLoader::ReadSinglePosition(const Fields& f, const ValueReader& world_values,
                                     EntryPlan* entry) {
  if (!f.Has("position"))
    file_->Fail(f.mark(),
                "a models entry needs 'distribute' (with 'count') to spread copies, or "
                "'position: [x, y]' for a single copy");
  if (f.Has("count")) {
    entry->count_field = f.Get("count");
    if (world_values.Integer(entry->count_field, 0, kMaxCount) != 1)
      file_->Fail(entry->count_field.mark, "'count' other than 1 needs 'distribute'");
  }
  const Field position = f.Get("position");
  entry->position_field = position;
  const std::vector<double> p = world_values.Numbers(position, 2, 3, kCoordinate);
  entry->fixed_pose.q = loader::ReadOrientation(world_values, f);
  entry->count = 1;
  entry->fixed_pose.p = {p[0], p[1], p.size() == 3 ? p[2] : -entry->FootprintOf(0).bottom};
}

}  // namespace swarmsim::loader
