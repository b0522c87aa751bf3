#include "swarm/loader/world_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <utility>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "modules/dynamics/height_range.h"
#include "swarm/loader/environment.h"
#include "swarm/loader/object_reader.h"
#include "swarm/loader/urdf.h"
#include "swarm/loader/world_loader_impl.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

// The loader's own top-level keys; the others are the registered modules'
// world-file sections (framework/world_section.h: metrics, paint, ...).
const std::vector<std::string> kTopKeys = {"simulation",   "parameters", "arena",   "obstacles",
                                           "environment",  "models",     "objects", "plugins",
                                           "package_path", "record"};

// Every top-level key a world file may give: the loader's, then the sections'.
std::vector<std::string> TopKeys(const ModuleRegistry& registry) {
  std::vector<std::string> keys = kTopKeys;
  for (const auto& section : registry.world_sections()) keys.push_back(section->key);
  return keys;
}

std::vector<Override> SplitOverrides(const LoadOptions& options) {
  std::vector<Override> out;
  for (const auto& [name, value] : options.overrides) {
    Override o{options.override_option + " " + name + "=" + value, "", name, value};
    if (const size_t dot = name.find('.'); dot != std::string::npos) {
      o.model = name.substr(0, dot);
      o.name = name.substr(dot + 1);
    }
    if (o.name.empty() || (o.model.empty() && name.find('.') != std::string::npos))
      throw Error(o.text + ": expected name=value or model.name=value");
    out.push_back(std::move(o));
  }
  return out;
}

// Once every object is there: the paths objects name (collections, distance
// and collision objects, sensors' detectable sets) through each type's check,
// so that a misspelled path is a load error at its file:line:col.
void CheckObjects(Scene& scene) {
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    if (!scene.alive_at(slot)) continue;
    const ObjectType type = scene.type_at(slot);
    const ObjectTypeDescriptor& descriptor = scene.type_descriptor(type);
    if (descriptor.check == nullptr) continue;
    RowTable* rows = scene.rows(type);
    descriptor.check(scene, scene.IdAt(slot),
                     rows != nullptr ? rows->At(scene.row_at(slot)) : nullptr);
  }
}

}  // namespace

// A --set value with the type of the parameter it replaces: a string
// parameter takes the text as is; a number or boolean must read as one.
ParamValue CoerceOverride(const Override& o, const ParamValue& declared,
                          const std::string& declared_where) {
  if (std::optional<ParamValue> value = loader::AsDeclaredType(o.value, declared)) return *value;
  throw Error(o.text + ": parameter '" + (o.model.empty() ? "" : o.model + ".") + o.name + "' is " +
              loader::TypeName(declared) + " (" + declared_where + "), got \"" + o.value + "\"");
}

LoadedWorld WorldLoader::Load() {
  file_ = std::make_unique<YamlFile>(
      YamlFile::Load(path_, "world file", "", loader::DisplayPath(path_)));
  const YamlFile& f = *file_;
  const Field root{
      "world", f.root(), f.root().Mark().is_null() ? YAML::Mark() : f.root().Mark(), {}};
  if (!f.root().IsMap())
    f.Fail(root.mark,
           "a world file must be a mapping with keys such as 'simulation', 'arena' and "
           "'models' (got " +
               loader::Describe(f.root()) + ")");
  Fields top(f, root, "the world file");
  top.Expect(TopKeys(registry_));
  overrides_ = SplitOverrides(options_);

  // Parameters first: every other value may use them.
  ReadParameters(top);
  ReadPackagePath(top);
  ReadModelEntries(top);
  CheckOverrides();

  LoadedWorld out;
  out.file = path_;
  out.warnings = warnings_;
  WorldSettings settings = ReadSimulation(top, &out.steps);
  if (std::shared_ptr<const ModuleRegistry> own = LoadPlugins(top))
    out.world = std::make_unique<World>(settings, std::move(own));
  else
    out.world = std::make_unique<World>(settings, registry_);
  World* world = out.world.get();
  world_registry_ = &world->registry();
  for (const auto& [name, value] : parameters_) world->parameters()[name] = value;

  ground_plane_ = settings.physics == "ode";
  placer_ = std::make_unique<Placer>(settings.seed);
  BuildArena(top, world);
  BuildObstacles(top, world);
  environment_field_ = top.Get("environment");
  environment_ = loader::ReadEnvironment(f, environment_field_, WorldValues(), path_.parent_path(),
                                         world->registry(), &out.warnings, &environment_format_);
  if (environment_) world->scene().set_environment(environment_);
  for (EntryPlan& entry : entries_) ResolveEntry(&entry);
  KeepPlacementClearOfTheMap(&out.warnings);
  AddLargeSwarmHints(settings, &out.warnings);
  AddPlaneWheelHints(settings, &out.warnings);
  unplaced_ = std::make_unique<Placer>(*placer_);
  PlaceEntries(&out.warnings);
  BuildCopies(world);
  // The scene's own objects (collections, distance objects, ...), after the
  // robots: they may name them.
  for (const loader::ObjectSpec& spec : loader::ReadSceneObjects(
           f, top.Get("objects"), WorldValues(), &scripts_, &meshes_, world_registry_))
    loader::AddToScene(spec, {}, &world->scene());
  CheckObjects(world->scene());
  // Modules' references (IK groups' obstacles) may name those objects too.
  world->CheckModuleReferences();
  ReadSections(top, world);
  out.metric_names = MetricNames(*world);
  out.models = Summarize();
  out.record_every = ReadRecord(top);
  return out;
}

// `record: true` or `record: {every: N}`: a recording every N steps (swarm/record).
int64_t WorldLoader::ReadRecord(const Fields& top) const {
  const Field record = top.Get("record");
  if (!record.present()) return 0;
  const ValueReader values = WorldValues();
  if (!record.node.IsMap()) return values.Bool(record) ? 1 : 0;
  Fields f(*file_, record, "'record'");
  f.Expect({"every"});
  return f.Has("every") ? values.Integer(f.Get("every"), 1, int64_t{1} << 40) : 1;
}

// --- Parameters ----------------------------------------------------------------------

void WorldLoader::ReadParameters(const Fields& top) {
  const Field params = top.Get("parameters");
  if (!params.present()) return;
  Fields fields(*file_, params, "'parameters'");
  // In file order: a parameter's expression may use the ones above it; the
  // ones below are named as such in messages.
  loader::ParametersBeingRead reading;
  for (const Field& p : fields.fields())
    reading.later.emplace(p.name, "line " + std::to_string(p.key_mark.line + 1));
  for (const Field& p : fields.fields()) {
    reading.current = p.name;
    reading.later.erase(p.name);
    if (!loader::IsParameterName(p.name))
      file_->Fail(p.key_mark,
                  "parameter name '" + p.name +
                      "' must be a Lua identifier (letters, digits, '_'; not a keyword)");
    if (!p.node.IsScalar() || !p.present())
      file_->Fail(p.mark, "parameter '" + p.name + "' must be a number, true/false or text (got " +
                              loader::Describe(p.node) + ")");
    ParamValue value =
        ValueReader(*file_, &expressions_, {&parameters_, nullptr, &reading}).Resolve(p);
    for (Override& o : overrides_) {
      if (!o.model.empty() || o.name != p.name) continue;
      value = CoerceOverride(o, value, file_->Where(p.mark));
      o.used = true;
    }
    parameters_[p.name] = value;
    parameter_fields_.emplace(p.name, p);
  }
}

// Whether `canonical` lies inside the world's folder or one of the program's
// plugin folders (symbolic links resolved on both sides).
bool WorldLoader::IsTrustedPluginLocation(const fs::path& canonical) const {
  std::vector<fs::path> roots{path_.parent_path()};
  roots.insert(roots.end(), options_.plugin_directories.begin(), options_.plugin_directories.end());
  for (const fs::path& root : roots) {
    std::error_code ec;
    const fs::path dir = fs::weakly_canonical(root.empty() ? fs::path(".") : root, ec);
    if (ec) continue;
    const fs::path relative = canonical.lexically_relative(dir);
    if (!relative.empty() && *relative.begin() != ".." && !relative.is_absolute()) return true;
  }
  return false;
}

// plugins: [name or path, ...]: a path (with '/' or ending in .so) is relative
// to the world file; a bare name is NAME.so in the world's folder, then in
// LoadOptions::plugin_directories. Null when the world names none.
std::shared_ptr<const ModuleRegistry> WorldLoader::LoadPlugins(const Fields& top) {
  const std::vector<Field> list = loader::ListElements(*file_, top.Get("plugins"), "plugins");
  if (list.empty()) return nullptr;
  auto registry = std::make_shared<ModuleRegistry>(registry_);
  const ValueReader values = WorldValues();
  for (const Field& element : list) {
    const std::string text = values.String(element);
    if (text.empty()) values.Fail(element, "a plugin must be a file or library name");
    std::vector<fs::path> candidates;
    if (text.find('/') != std::string::npos || text.ends_with(".so")) {
      candidates.push_back(path_.parent_path() / text);
    } else {
      candidates.push_back(path_.parent_path() / (text + ".so"));
      for (const fs::path& dir : options_.plugin_directories)
        candidates.push_back(dir / (text + ".so"));
    }
    std::error_code ec;
    const auto found = std::find_if(candidates.begin(), candidates.end(),
                                    [&](const fs::path& p) { return fs::is_regular_file(p, ec); });
    if (found == candidates.end()) {
      std::string tried;
      for (const fs::path& p : candidates) tried += (tried.empty() ? "" : ", ") + p.string();
      // One that is there but no ordinary file (a folder, a link to a
      // device) was "not found".
      for (const fs::path& p : candidates)
        if (fs::exists(p, ec))
          values.Fail(element, "plugin '" + text + "': '" + p.string() +
                                   "' is there but is no ordinary file (a folder, a device or a "
                                   "pipe, perhaps through a link)");
      values.Fail(element, "plugin '" + text + "' not found (looked for " + tried + ")");
    }
    // Loaded already (--plugin): its commands are there.
    const fs::path canonical = fs::weakly_canonical(*found, ec);
    if (registry->HasPlugin(ec ? found->string() : canonical.string())) continue;
    // A plugin is native code: a world may load one from its own folder or
    // the program's plugin folders; anything else takes --trust-scripts (or
    // --plugin), as scripts need it to reach outside the world's folder.
    if (!options_.trust_scripts && !IsTrustedPluginLocation(canonical))
      values.Fail(element,
                  "plugin '" + text + "' resolves to " + canonical.string() +
                      ", outside the world's folder (" +
                      fs::weakly_canonical(fs::absolute(path_).parent_path(), ec).string() +
                      ") and the program's plugin folders; a world may load native "
                      "code only from there (load it with --plugin PATH, or pass "
                      "--trust-scripts)");
    try {
      LoadPlugin(found->string(), registry.get());
    } catch (const Error& e) {
      values.Fail(element, e.what());
    }
  }
  return registry;
}

// package_path: [folder, ...], relative to the world file: where the ROS
// packages of URDF models' package:// URIs are looked for (before --package-path).
void WorldLoader::ReadPackagePath(const Fields& top) {
  const ValueReader values = WorldValues();
  for (const Field& element :
       loader::ListElements(*file_, top.Get("package_path"), "package_path folders")) {
    const std::string text = values.String(element);
    if (text.empty()) values.Fail(element, "a 'package_path' folder must be a non-empty path");
    const fs::path dir = path_.parent_path() / text;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
      values.Fail(element, "package_path folder '" + text + "' is not a folder (looked for " +
                               loader::DisplayPath(dir) + ")");
    package_path_.push_back(dir);
  }
  for (const fs::path& dir : options_.package_path) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
      throw Error("--package-path " + dir.string() + ": not a folder");
    package_path_.push_back(dir);
  }
}

const ModelFile& WorldLoader::LoadModel(const Field& field, const std::string& text) {
  const fs::path path = path_.parent_path() / text;
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (ec) key = path.lexically_normal();
  auto it = models_.find(key);
  if (it == models_.end() && loader::IsUrdfFile(text)) {
    // A URDF robot: imported once; the entry's keys are read in the world file.
    const std::string where = file_->Where(field.mark);
    loader::UrdfImport urdf = loader::ImportUrdf(path, where, text, package_path_, &meshes_);
    auto model = std::make_unique<ModelFile>(ModelFile{*file_,
                                                       urdf.name,
                                                       {},
                                                       {},
                                                       {},
                                                       nullptr,
                                                       text,
                                                       std::move(urdf.summary),
                                                       std::move(urdf.merged_joints)});
    model->imported = std::make_shared<const ObjectSpec>(std::move(urdf.root));
    warnings_.insert(warnings_.end(), urdf.warnings.begin(), urdf.warnings.end());
    it = models_.emplace(key, std::move(model)).first;
  }
  if (it == models_.end()) {
    const std::string where = file_->Where(field.mark);
    auto model = std::make_unique<ModelFile>(loader::ReadModelFile(
        YamlFile::Load(path, "model file", where, text), where, ModelSectionKeys(registry_)));
    it = models_.emplace(key, std::move(model)).first;
  }
  return *it->second;
}

void WorldLoader::ReadModelEntries(const Fields& top) {
  for (const Field& element : loader::ListElements(*file_, top.Get("models"), "model entries")) {
    Fields entry(*file_, element, "a models entry");
    // A misspelled 'model' is an unknown key (with a suggestion), not a missing one.
    if (!entry.Has("model")) entry.Expect(EntryKeys(registry_));
    const Field model = entry.Require("model");
    if (!model.node.IsScalar())
      file_->Fail(model.mark,
                  "'model' must be the path of a model file, e.g. models/footbot.yaml "
                  "(got " +
                      loader::Describe(model.node) + ")");
    EntryPlan plan;
    plan.field = element;
    // A world parameter may name it (`model: $robot_file`, set by --set or a sweep).
    plan.model = &LoadModel(model, WorldValues().String(model));
    entries_.push_back(std::move(plan));
  }
}

namespace {

// The keys of a world's simulation: section (backends add their own).
constexpr const char* kSimulationKeys[] = {"physics",
                                           "time_step",
                                           "physics_substeps",
                                           "physics_partitions",
                                           "seed",
                                           "duration",
                                           "steps",
                                           "gravity",
                                           "octree_resolution",
                                           "main_script",
                                           "instruction_budget",
                                           "script_memory_mb",
                                           "run_script_memory_mb",
                                           "robots_per_lua_state",
                                           "step_timeout",
                                           "on_script_error"};

// "; simulation: settings are not --set parameters: ..." when `o` names
// one (--set simulation.physics=planar, --set robots_per_lua_state=1).
std::string SimulationKeyHint(const std::string& model, const std::string& name) {
  bool key = false;
  for (const char* k : kSimulationKeys) key |= name == k;
  if (model != "simulation" && !(model.empty() && key)) return "";
  const std::string example = key ? name : "physics";
  return "; the world file's simulation: settings are not parameters --set can change: make " +
         std::string("one a parameter (under parameters:, `") + example +
         ": <its value>`, and in simulation:, `" + example + ": $" + example + "`), then --set " +
         example + "=...";
}

}  // namespace

void WorldLoader::CheckOverrides() {
  // Every --set must name a parameter; the suggestion spans world and model ones.
  std::vector<std::string> known;
  for (const auto& [name, value] : parameters_) known.push_back(name);
  for (const auto& [path, model] : models_)
    for (const auto& p : model->parameters) known.push_back(model->name + "." + p.name);
  for (Override& o : overrides_) {
    if (o.used) continue;
    if (o.model.empty()) {
      // A model parameter given without its model: point at the full name.
      for (const std::string& k : known)
        if (k.ends_with("." + o.name))
          throw Error(o.text + ": no world parameter '" + o.name + "' in " + file_->name() +
                      "; did you mean '" + k + "'?");
      if (const std::string hint = SimulationKeyHint("", o.name); !hint.empty())
        throw Error(o.text + ": no parameter '" + o.name + "' in " + file_->name() + hint);
      throw Error(o.text + ": no parameter '" + o.name + "' in " + file_->name() +
                  loader::Suggest(o.name, known));
    }
    const ModelFile* model = nullptr;
    for (const auto& [path, m] : models_)
      if (m->name == o.model) model = m.get();
    const std::string full = o.model + "." + o.name;
    if (!model)
      throw Error(o.text + ": no model '" + o.model + "' in " + file_->name() +
                  (o.model == "simulation" ? SimulationKeyHint(o.model, o.name)
                                           : loader::Suggest(full, known)));
    bool found = false;
    for (const auto& p : model->parameters) found |= p.name == o.name;
    if (!found)
      throw Error(o.text + ": model '" + o.model + "' has no parameter '" + o.name + "'" +
                  loader::Suggest(full, known));
  }
}

// --- Simulation ----------------------------------------------------------------------

WorldSettings WorldLoader::ReadSimulation(const Fields& top, std::optional<int64_t>* steps) {
  WorldSettings s;
  s.file = file_->name();
  std::error_code ec;
  s.directory = fs::absolute(path_, ec).parent_path();
  s.threads = options_.threads;
  s.output_directory = options_.output_directory;
  s.trust_scripts = options_.trust_scripts;
  s.max_memory = options_.max_memory;
  const ValueReader values = WorldValues();
  const Field sim = top.Get("simulation");
  if (sim.present()) {
    Fields f(*file_, sim, "'simulation'");
    // The loader's keys, and a mapping per backend with settings of its own
    // (`ode: {...}`: ModuleRegistry::RegisterDynamicsSection).
    std::vector<std::string> known(std::begin(kSimulationKeys), std::end(kSimulationKeys));
    for (const std::string& name : registry_.DynamicsNames())
      if (registry_.FindDynamicsSection(name)) known.push_back(name);
    f.Expect(std::span<const std::string>(known));
    if (f.Has("main_script")) {
      const Field main = f.Get("main_script");
      const std::string text = values.String(main);
      if (text.empty()) values.Fail(main, "'main_script' must be a file name");
      s.main_script = scripts_.Get(path_.parent_path() / text, file_->Where(main.mark), text);
    }
    if (f.Has("instruction_budget"))
      s.instruction_budget = values.Integer(f.Get("instruction_budget"), 0, int64_t{1} << 40);
    if (f.Has("script_memory_mb"))
      s.script_memory_limit = values.Integer(f.Get("script_memory_mb"), 0, int64_t{1} << 30) << 20;
    if (f.Has("run_script_memory_mb"))
      s.run_script_memory_limit = values.Integer(f.Get("run_script_memory_mb"), 0, int64_t{1} << 30)
                                  << 20;
    robots_per_lua_state_given_ = f.Has("robots_per_lua_state");
    physics_partitions_given_ = f.Has("physics_partitions");
    if (robots_per_lua_state_given_)
      s.robots_per_lua_state =
          static_cast<int>(values.Integer(f.Get("robots_per_lua_state"), 1, 4096));
    if (f.Has("step_timeout"))
      s.step_timeout =
          values.Number(f.Get("step_timeout"), {"a non-negative number of seconds", 0, 1e9});
    if (f.Has("on_script_error"))
      s.on_script_error =
          values.Choice(f.Get("on_script_error"), {"stop", "disable_script"}) == "stop"
              ? ScriptErrorPolicy::kStop
              : ScriptErrorPolicy::kDisableScript;
    {
      // The default backend must exist too (a test registry may lack it).
      const Field physics =
          f.Has("physics") ? f.Get("physics") : Field{"physics", {}, sim.mark, sim.mark};
      if (f.Has("physics")) s.physics = values.String(physics);
      if (!registry_.HasDynamics(s.physics)) {
        const std::vector<std::string> names = registry_.DynamicsNames();
        std::string list;
        for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
        const std::string hint = loader::Suggest(s.physics, names);
        values.Fail(physics, (f.Has("physics") ? "unknown" : "the default") +
                                 std::string(" physics backend '") + s.physics + "'" +
                                 (hint.starts_with(";") ? hint : "") +
                                 " (available: " + (list.empty() ? "none" : list) + ")");
      }
    }
    // Each backend's own mapping is read and checked whatever `physics` is
    // (a bad value is an error either way); the chosen backend's is used.
    for (const std::string& name : registry_.DynamicsNames()) {
      const DynamicsSection* section = registry_.FindDynamicsSection(name);
      if (!section || !f.Has(name)) continue;
      const FieldsObjectReader sim_reader(values, f, nullptr, &registry_);
      const std::unique_ptr<ObjectReader> r =
          sim_reader.Map(name, "'simulation." + name + "'", "a mapping of " + name + " settings");
      if (!r) continue;
      std::vector<std::string> keys;
      for (const ObjectKey& key : section->keys) keys.emplace_back(key.name);
      r->Expect(keys);
      std::shared_ptr<const DynamicsOptions> options = section->read(*r);
      if (name == s.physics) s.physics_options = std::move(options);
    }
    if (f.Has("time_step"))
      s.time_step =
          values.Number(f.Get("time_step"), {"a positive number of seconds", 0, 3600, true});
    if (f.Has("physics_substeps"))
      s.physics_substeps = static_cast<int>(values.Integer(f.Get("physics_substeps"), 1, 1000));
    if (f.Has("physics_partitions")) {
      // auto: the backend chooses from the scene (never from the thread count).
      const Field partitions = f.Get("physics_partitions");
      // Written, or from a parameter ($parts: a sweep over 1 and auto);
      // Integer reads a count given as text (--set parts=4 on a parameter
      // declared as auto).
      const ParamValue value =
          partitions.node.IsScalar() ? values.Resolve(partitions) : ParamValue(0.0);
      if (const std::string* text = std::get_if<std::string>(&value); text && *text == "auto")
        s.physics_partitions = 0;
      else
        s.physics_partitions = static_cast<int>(
            values.Integer(partitions, 1, 1024, "auto or a whole number from 1 to 1024"));
    }
    if (f.Has("seed")) s.seed = values.Seed(f.Get("seed"));
    if (f.Has("gravity"))
      s.gravity = values.Number(f.Get("gravity"), {"a non-negative number (m/s^2)", 0, 1e4});
    if (f.Has("octree_resolution"))
      s.octree_resolution = values.Number(f.Get("octree_resolution"), kPositiveLength);
    if (f.Has("duration") && f.Has("steps"))
      values.Fail(f.Get("steps"), "give either 'duration' (seconds) or 'steps', not both");
    if (f.Has("steps")) *steps = values.Integer(f.Get("steps"), 0, int64_t{1} << 40);
    if (f.Has("duration")) {
      const double duration =
          values.Number(f.Get("duration"), {"a positive number of seconds", 0, 1e9, true});
      const double n = StepsInDuration(duration, s.time_step);
      if (n > static_cast<double>(int64_t{1} << 40))
        values.Fail(f.Get("duration"), "'duration' is too many steps of 'time_step'");
      // As --duration: not a silent run of 0 steps, nor of 1 for a duration
      // --duration refuses (0.05 s of 0.1 s steps ran one step).
      if (duration > 0 && (n < 1 || duration < s.time_step))
        values.Fail(f.Get("duration"), "'duration' " + loader::FormatNumber(duration) +
                                           " s is shorter than one time step (" +
                                           loader::FormatNumber(s.time_step) + " s)");
      *steps = static_cast<int64_t>(n);
    }
  }
  if (!registry_.HasDynamics(s.physics))
    file_->Fail(top.mark(),
                "the world names no 'simulation: {physics: ...}' and the default backend '" +
                    s.physics + "' is not available");
  if (options_.seed) s.seed = *options_.seed;
  return s;
}

// --- Arena and obstacles ------------------------------------------------------------------

void WorldLoader::AddObstacleFootprint(const ShapeData& shape, const Pose& X_WO) {
  Obstacle2 o;
  o.x = X_WO.p.x;
  o.y = X_WO.p.y;
  const dynamics::HeightRange heights = dynamics::CalcHeightRange(shape, X_WO);
  o.lo = heights.lo;
  o.hi = heights.hi;
  const Vec3 z = X_WO.q.Rotate({0, 0, 1});
  if (shape.kind == ShapeKind::kSphere ||
      (shape.kind == ShapeKind::kCylinder && std::abs(z.z) > 1 - 1e-9)) {
    o.kind = Obstacle2::Kind::kCircle;
    o.radius = shape.size.x;
  } else if (shape.kind == ShapeKind::kBox && std::abs(z.z) > 1 - 1e-9) {
    o.kind = Obstacle2::Kind::kBox;
    o.half_x = shape.size.x / 2;
    o.half_y = shape.size.y / 2;
    o.yaw = X_WO.q.Yaw();
  } else if (shape.kind == ShapeKind::kMesh && shape.mesh) {
    // The plane box around the projected vertices (conservative).
    double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
    for (const Vec3& v : shape.mesh->vertices()) {
      const Vec3 p = X_WO * v;
      lo_x = std::min(lo_x, p.x), lo_y = std::min(lo_y, p.y);
      hi_x = std::max(hi_x, p.x), hi_y = std::max(hi_y, p.y);
    }
    o.kind = Obstacle2::Kind::kBox;
    o.x = (lo_x + hi_x) / 2;
    o.y = (lo_y + hi_y) / 2;
    o.half_x = (hi_x - lo_x) / 2;
    o.half_y = (hi_y - lo_y) / 2;
  } else {
    // Tilted: the plane box around the rotated shape (conservative).
    const Vec3 half = shape.kind == ShapeKind::kBox
                          ? shape.size * 0.5
                          : Vec3{shape.size.x, shape.size.x, shape.size.z / 2};
    const Vec3 cx = X_WO.q.Rotate({half.x, 0, 0}), cy = X_WO.q.Rotate({0, half.y, 0}),
               cz = X_WO.q.Rotate({0, 0, half.z});
    o.kind = Obstacle2::Kind::kBox;
    o.half_x = std::abs(cx.x) + std::abs(cy.x) + std::abs(cz.x);
    o.half_y = std::abs(cx.y) + std::abs(cy.y) + std::abs(cz.y);
  }
  placer_->AddObstacle(o);
}

void WorldLoader::BuildArena(const Fields& top, World* world) {
  const Field arena = top.Get("arena");
  if (!arena.present()) return;
  const ValueReader values = WorldValues();
  Fields f(*file_, arena, "'arena'");
  f.Expect({"size", "wall_thickness", "wall_height"});
  const Field size = f.Require("size");
  double w, h;
  if (size.node.IsSequence()) {
    const std::vector<double> v = values.Numbers(size, 2, 2, kPositiveLength);
    w = v[0], h = v[1];
  } else {
    w = h = values.Number(size, {"a positive number or [width, depth]", 0, kMaxLength, true});
  }
  const double t =
      f.Has("wall_thickness") ? values.Number(f.Get("wall_thickness"), kPositiveLength) : 0.1;
  const double height =
      f.Has("wall_height") ? values.Number(f.Get("wall_height"), kPositiveLength) : 0.2;
  arena_ = Region2{-w / 2, -h / 2, w / 2, h / 2};
  // Four static walls around the inner area; the north and south ones span the corners.
  struct Wall {
    const char* name;
    Vec3 p, size;
  };
  const Wall walls[] = {
      {"wall_north", {0, h / 2 + t / 2, height / 2}, {w + 2 * t, t, height}},
      {"wall_south", {0, -h / 2 - t / 2, height / 2}, {w + 2 * t, t, height}},
      {"wall_east", {w / 2 + t / 2, 0, height / 2}, {t, h, height}},
      {"wall_west", {-w / 2 - t / 2, 0, height / 2}, {t, h, height}},
  };
  for (const Wall& wall : walls) {
    ShapeData shape;
    shape.kind = ShapeKind::kBox;
    shape.size = wall.size;
    shape.dynamic = false;
    const Pose X_WO{wall.p, {}};
    world->scene().AddShape(wall.name, {}, X_WO, shape);
    AddObstacleFootprint(shape, X_WO);
  }
}

void WorldLoader::BuildObstacles(const Fields& top, World* world) {
  const ValueReader values = WorldValues();
  std::vector<std::string> keys = loader::ShapeKeys();
  keys.insert(keys.end(), loader::PoseKeys().begin(), loader::PoseKeys().end());
  keys.push_back("name");
  int index = 0;
  for (const Field& element : loader::ListElements(*file_, top.Get("obstacles"), "obstacles")) {
    Fields f(*file_, element, "obstacle " + std::to_string(index));
    f.Expect(keys);
    std::string name = "obstacle_" + std::to_string(index);
    if (f.Has("name")) {  // a path element, as a model's object names ('a/b' was found by no path)
      name = values.String(f.Get("name"));
      loader::CheckObjectName(values, f.Get("name"), name);
    }
    const ShapeData shape = loader::ReadShape(values, f, &meshes_);
    const Pose X_WO = loader::ReadPose(values, f);
    world->scene().AddShape(name, {}, X_WO, shape);
    AddObstacleFootprint(shape, X_WO);
    ++index;
  }
}
// --- Modules' sections ---------------------------------------------------------------------

// The registered world-file sections (metrics:, paint:, ...), each read by
// its module through an ObjectReader over the top level, in registration
// order, whether its key is there or not.
void WorldLoader::ReadSections(const Fields& top, World* world) {
  const ValueReader values = WorldValues();
  const FieldsObjectReader reader(values, top, &meshes_, world_registry_);
  WorldSectionContext context;
  if (arena_) context.arena = {arena_->min_x, arena_->min_y, arena_->max_x, arena_->max_y};
  context.world_folder = path_.parent_path();
  for (const auto& section : registry_.world_sections()) section->read(reader, context, world);
}

// The metric modules the world made (kind "metric"), in creation order: the
// columns a recording declares up front.
std::vector<std::string> WorldLoader::MetricNames(const World& world) const {
  std::vector<std::string> names;
  for (const std::string& name : world.module_names()) {
    const ModuleDescriptor* module = world.registry().FindModule(name);
    if (module != nullptr && module->info.kind == "metric") names.push_back(name);
  }
  return names;
}

}  // namespace swarmsim::loader

namespace swarmsim {

LoadedWorld LoadWorld(const std::filesystem::path& file, const LoadOptions& options,
                      const ModuleRegistry& registry) {
  auto loader = std::make_shared<loader::WorldLoader>(file, options, registry);
  try {
    LoadedWorld out = loader->Load();
    out.placement = [loader](uint64_t seed) { return loader->Placements(seed); };
    return out;
  } catch (const Error&) {
    throw;
  } catch (const YAML::Exception& e) {
    // A yaml-cpp conversion the checks above missed: still a message, never a crash.
    throw Error(loader::DisplayPath(file) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw Error(loader::DisplayPath(file) + ": out of memory while loading the world");
  }
}

double StepsInDuration(double duration, double time_step) {
  const double q = duration / time_step;
  return std::floor(q + 0.5 + 1e-9 * std::max(1.0, q));
}

}  // namespace swarmsim
