#include "swarm/loader/world_loader.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>
#include <utility>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "swarm/loader/ik.h"
#include "swarm/loader/model.h"
#include "swarm/loader/paint.h"
#include "swarm/loader/placement.h"
#include "swarm/loader/values.h"
#include "swarm/loader/yaml.h"

namespace swarmsim {

namespace fs = std::filesystem;
using loader::Field;
using loader::Fields;
using loader::ModelFile;
using loader::ObjectSpec;
using loader::ValueReader;
using loader::YamlFile;

namespace {

constexpr int64_t kMaxCount = 1000000;  // copies per models entry
constexpr double kDegToRad = M_PI / 180.0;

const std::vector<std::string> kTopKeys = {"simulation", "parameters", "arena", "obstacles",
                                           "models",     "metrics",    "paint", "plugins"};

const std::vector<std::string> kEntryKeys = {"model",      "count",       "distribute",
                                             "position",   "heading_deg", "orientation_deg",
                                             "parameters", "instances",   "scale"};

// One --set, split into its target.
struct Override {
  std::string text;   // "name=value", for messages
  std::string model;  // "" for a world parameter
  std::string name;
  std::string value;
  bool used = false;
};

// A --set value with the type of the parameter it replaces: a string
// parameter takes the text as is; a number or boolean must read as one.
ParamValue CoerceOverride(const Override& o, const ParamValue& declared,
                          const std::string& declared_where) {
  const ParamValue parsed = loader::ParseScalar(o.value, false);
  if (std::holds_alternative<std::string>(declared)) return o.value;
  if (parsed.index() == declared.index()) return parsed;
  throw Error("--set " + o.text + ": parameter '" + (o.model.empty() ? "" : o.model + ".") +
              o.name + "' is " + loader::TypeName(declared) + " (" + declared_where + "), got \"" +
              o.value + "\"");
}

std::vector<Override> SplitOverrides(const LoadOptions& options) {
  std::vector<Override> out;
  for (const auto& [name, value] : options.overrides) {
    Override o{name + "=" + value, "", name, value};
    if (const size_t dot = name.find('.'); dot != std::string::npos) {
      o.model = name.substr(0, dot);
      o.name = name.substr(dot + 1);
    }
    if (o.name.empty() || (o.model.empty() && name.find('.') != std::string::npos))
      throw Error("--set " + o.text + ": expected name=value or model.name=value");
    out.push_back(std::move(o));
  }
  return out;
}

// How one `models:` entry places its copies.
struct EntryPlan {
  Field field;
  const ModelFile* model = nullptr;
  std::shared_ptr<ParameterSet> parameters;
  ObjectSpec spec;
  loader::Footprint footprint;  // of the scaled model
  double scale = 1;             // size factor of every copy (`scale:`)
  // Either one copy at a fixed pose, or `count` distributed copies.
  bool distribute = false;
  Pose fixed_pose;
  Field position_field;
  Field count_field;
  int64_t count = 1;
  Region2 region;
  std::string region_text;  // "the arena", "the region [..] - [..]"
  double clearance = 0;
  std::optional<double> heading;
  std::vector<Placement2> placements;
  std::vector<loader::IkGroupDef> ik_groups;
  // instances: [{index, parameters}]: copies with their own values, in file order.
  struct OwnCopy {
    int64_t index = 0;
    Field field;  // the instances element, for messages
    std::shared_ptr<ParameterSet> parameters;
    // The copy's objects, resolved with its own values (a size, a range, a
    // limit may use them); absent when its values equal the entry's, so it
    // is duplicated from the entry's first copy like the others.
    std::optional<ObjectSpec> spec;
    loader::Footprint footprint;  // of the scaled copy (spec present)
    std::vector<loader::IkGroupDef> ik_groups;
  };
  std::vector<OwnCopy> own_copies;
  std::map<int64_t, size_t> own_copy_of;  // copy index -> own_copies position

  // The copy's own values and objects, or null when it has none.
  const OwnCopy* FindOwnCopy(int64_t k) const {
    const auto it = own_copy_of.find(k);
    return it == own_copy_of.end() ? nullptr : &own_copies[it->second];
  }
  // The objects copy k is built from, and its footprint.
  const ObjectSpec& SpecOf(int64_t k) const {
    const OwnCopy* own = FindOwnCopy(k);
    return own && own->spec ? *own->spec : spec;
  }
  const loader::Footprint& FootprintOf(int64_t k) const {
    const OwnCopy* own = FindOwnCopy(k);
    return own && own->spec ? own->footprint : footprint;
  }
  // The largest footprint radius of the `count` copies.
  double MaxFootprintRadius() const {
    if (own_copies.empty()) return footprint.radius;
    double r = 0;
    for (int64_t k = 0; k < count; ++k) r = std::max(r, FootprintOf(k).radius);
    return r;
  }
};

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

// The script files of a model's objects, in tree order, each with the
// objects it is attached to, as paths from the model root (':' the root
// itself, ':/a/b' below it) marked "(explicit)" where it runs only through
// sim.handleChildScript: {file, "on :/leg0, :/leg1 (explicit)"}.
void CollectScripts(const ObjectSpec& spec, const std::string& path,
                    std::vector<std::pair<std::string, std::string>>* out) {
  if (spec.script) {
    auto it = std::find_if(out->begin(), out->end(),
                           [&](const auto& s) { return s.first == spec.script->path; });
    if (it == out->end()) it = out->insert(out->end(), {spec.script->path, "on"});
    it->second +=
        (it->second == "on" ? " " : ", ") + path + (spec.script_explicit ? " (explicit)" : "");
  }
  for (const ObjectSpec& child : spec.children)
    CollectScripts(child, (path == ":" ? ":/" : path + "/") + child.name, out);
}

// Scaled mesh assets of one entry, by the asset they scale.
using ScaledMeshes = std::map<const TriangleMesh*, std::shared_ptr<const TriangleMesh>>;

// Points the mesh shapes of the copy at `id` (built from `spec`, then scaled)
// at the assets an earlier copy of the entry was scaled to, so that copies
// built from their own description share them as duplicates do.
void ShareScaledMeshes(const ObjectSpec& spec, ObjectId id, Scene* scene, ScaledMeshes* scaled) {
  const ShapeData* shape = spec.As<ShapeData>(ObjectType::kShape);
  if (shape != nullptr && shape->mesh) {
    const auto [it, added] = scaled->emplace(shape->mesh.get(), scene->shape(id).mesh);
    if (!added) scene->mutable_shape(id).mesh = it->second;
  }
  const std::vector<ObjectId> children = scene->children(id);
  for (size_t i = 0; i < spec.children.size() && i < children.size(); ++i)
    ShareScaledMeshes(spec.children[i], children[i], scene, scaled);
}

class WorldLoader {
 public:
  WorldLoader(const fs::path& file, const LoadOptions& options, const ModuleRegistry& registry)
      : path_(file), options_(options), registry_(registry) {}

  LoadedWorld Load();

 private:
  void ReadParameters(const Fields& top);
  std::shared_ptr<const ModuleRegistry> LoadPlugins(const Fields& top);
  bool IsTrustedPluginLocation(const fs::path& canonical) const;
  void ReadModelEntries(const Fields& top);
  void CheckOverrides();
  WorldSettings ReadSimulation(const Fields& top, std::optional<int64_t>* steps);
  void BuildArena(const Fields& top, World* world);
  void BuildObstacles(const Fields& top, World* world);
  void AddObstacleFootprint(const ShapeData& shape, const Pose& X_WO);
  void ResolveEntry(EntryPlan* entry);
  void PlaceEntries();
  void BuildCopies(World* world);
  std::vector<SwarmMetricSpec> ReadMetrics(const Fields& top, World* world);
  std::vector<ModelSummary> Summarize() const;

  const ModelFile& LoadModel(const Field& field, const std::string& text);
  ValueReader WorldValues() const {
    return ValueReader(*file_, &expressions_, {&parameters_, nullptr});
  }

  fs::path path_;
  const LoadOptions& options_;
  const ModuleRegistry& registry_;
  const ModuleRegistry* world_registry_ = nullptr;  // registry_ plus the world's plugins
  std::unique_ptr<YamlFile> file_;
  mutable loader::Expressions expressions_;
  loader::ScriptCache scripts_;
  loader::MeshCache meshes_;  // each mesh file read once per world
  std::vector<Override> overrides_;
  ParameterSet parameters_;
  std::map<std::string, Field> parameter_fields_;  // where each world parameter is set
  std::map<fs::path, std::unique_ptr<ModelFile>> models_;
  std::vector<EntryPlan> entries_;
  std::optional<Region2> arena_;
  std::unique_ptr<Placer> placer_;
};

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
  top.Expect(kTopKeys);
  overrides_ = SplitOverrides(options_);

  // Parameters first: every other value may use them.
  ReadParameters(top);
  ReadModelEntries(top);
  CheckOverrides();

  LoadedWorld out;
  out.file = path_;
  WorldSettings settings = ReadSimulation(top, &out.steps);
  if (std::shared_ptr<const ModuleRegistry> own = LoadPlugins(top))
    out.world = std::make_unique<World>(settings, std::move(own));
  else
    out.world = std::make_unique<World>(settings, registry_);
  World* world = out.world.get();
  world_registry_ = &world->registry();
  for (const auto& [name, value] : parameters_) world->parameters()[name] = value;

  placer_ = std::make_unique<Placer>(settings.seed);
  BuildArena(top, world);
  BuildObstacles(top, world);
  for (EntryPlan& entry : entries_) ResolveEntry(&entry);
  PlaceEntries();
  BuildCopies(world);
  out.metrics = ReadMetrics(top, world);
  out.models = Summarize();
  loader::AddPaintLayer(f, root, top.Get("paint"), WorldValues(), arena_, world);
  return out;
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

const ModelFile& WorldLoader::LoadModel(const Field& field, const std::string& text) {
  const fs::path path = path_.parent_path() / text;
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (ec) key = path.lexically_normal();
  auto it = models_.find(key);
  if (it == models_.end()) {
    const std::string where = file_->Where(field.mark);
    auto model = std::make_unique<ModelFile>(
        loader::ReadModelFile(YamlFile::Load(path, "model file", where, text), where));
    it = models_.emplace(key, std::move(model)).first;
  }
  return *it->second;
}

void WorldLoader::ReadModelEntries(const Fields& top) {
  for (const Field& element : loader::ListElements(*file_, top.Get("models"), "model entries")) {
    Fields entry(*file_, element, "a models entry");
    // A misspelled 'model' is an unknown key (with a suggestion), not a missing one.
    if (!entry.Has("model")) entry.Expect(kEntryKeys);
    const Field model = entry.Require("model");
    if (!model.node.IsScalar())
      file_->Fail(model.mark,
                  "'model' must be the path of a model file, e.g. models/footbot.yaml "
                  "(got " +
                      loader::Describe(model.node) + ")");
    EntryPlan plan;
    plan.field = element;
    plan.model = &LoadModel(model, model.node.Scalar());
    entries_.push_back(std::move(plan));
  }
}

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
          throw Error("--set " + o.text + ": no world parameter '" + o.name + "' in " +
                      file_->name() + "; did you mean '" + k + "'?");
      throw Error("--set " + o.text + ": no parameter '" + o.name + "' in " + file_->name() +
                  loader::Suggest(o.name, known));
    }
    const ModelFile* model = nullptr;
    for (const auto& [path, m] : models_)
      if (m->name == o.model) model = m.get();
    const std::string full = o.model + "." + o.name;
    if (!model)
      throw Error("--set " + o.text + ": no model '" + o.model + "' in " + file_->name() +
                  loader::Suggest(full, known));
    bool found = false;
    for (const auto& p : model->parameters) found |= p.name == o.name;
    if (!found)
      throw Error("--set " + o.text + ": model '" + o.model + "' has no parameter '" + o.name +
                  "'" + loader::Suggest(full, known));
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
  const ValueReader values = WorldValues();
  const Field sim = top.Get("simulation");
  if (sim.present()) {
    Fields f(*file_, sim, "'simulation'");
    f.Expect({"physics", "time_step", "physics_substeps", "seed", "duration", "steps", "gravity",
              "octree_resolution", "main_script", "instruction_budget", "script_memory_mb",
              "step_timeout", "on_script_error"});
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
    if (f.Has("time_step"))
      s.time_step =
          values.Number(f.Get("time_step"), {"a positive number of seconds", 0, 3600, true});
    if (f.Has("physics_substeps"))
      s.physics_substeps = static_cast<int>(values.Integer(f.Get("physics_substeps"), 1, 1000));
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
      const double n = std::round(duration / s.time_step);
      if (n > static_cast<double>(int64_t{1} << 40))
        values.Fail(f.Get("duration"), "'duration' is too many steps of 'time_step'");
      if (duration > 0 && n < 1)  // as --duration: not a silent run of 0 steps
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
    if (f.Has("name")) name = values.String(f.Get("name"));
    const ShapeData shape = loader::ReadShape(values, f, &meshes_);
    const Pose X_WO = loader::ReadPose(values, f);
    world->scene().AddShape(name, {}, X_WO, shape);
    AddObstacleFootprint(shape, X_WO);
    ++index;
  }
}

// --- Models ------------------------------------------------------------------------------

void WorldLoader::ResolveEntry(EntryPlan* entry) {
  const ModelFile& model = *entry->model;
  const ValueReader world_values = WorldValues();
  Fields f(*file_, entry->field, "the models entry for '" + model.name + "'");
  f.Expect(kEntryKeys);

  // Model parameters: declared defaults, then this entry's values, then --set.
  auto params = std::make_shared<ParameterSet>();
  std::map<std::string, std::string> declared_where;
  std::vector<std::string> names;
  {
    const ValueReader defaults(model.file, &expressions_, {&parameters_, nullptr});
    for (const auto& decl : model.parameters) {
      (*params)[decl.name] = defaults.Resolve(decl.default_value);
      declared_where[decl.name] = model.file.Where(decl.default_value.mark);
      names.push_back(decl.name);
    }
  }
  // Values given in the world file (the entry's, or one instance's) over `set`.
  auto apply = [&](const Field& field, ParameterSet* set) {
    Fields given(*file_, field, "the parameters of model '" + model.name + "'");
    for (const Field& p : given.fields()) {
      auto it = set->find(p.name);
      if (it == set->end())
        file_->Fail(p.key_mark,
                    "model '" + model.name + "' has no parameter '" + p.name + "'" +
                        (names.empty() ? " (it declares none)" : loader::Suggest(p.name, names)));
      const ParamValue value = world_values.Resolve(p);
      if (value.index() != it->second.index() && !std::holds_alternative<std::string>(it->second))
        file_->Fail(p.mark, "parameter '" + p.name + "' of model '" + model.name + "' is " +
                                loader::TypeName(it->second) + " (" + declared_where[p.name] +
                                "), got " + loader::Describe(p.node));
      it->second = std::holds_alternative<std::string>(it->second)
                       ? ParamValue(ParamToString(value))
                       : value;
      for (const auto& decl : model.parameters)
        if (decl.name == p.name)
          if (std::string e = RangeError(decl, model.name, it->second); !e.empty())
            file_->Fail(p.mark, e);
    }
  };
  for (const auto& decl : model.parameters)
    if (std::string e = RangeError(decl, model.name, (*params)[decl.name]); !e.empty())
      model.file.Fail(decl.default_value.mark, "the default of " + e);
  if (f.Has("parameters")) apply(f.Get("parameters"), params.get());
  for (Override& o : overrides_) {
    if (o.model != model.name) continue;
    auto it = params->find(o.name);
    it->second = CoerceOverride(o, it->second, declared_where[o.name]);
    for (const auto& decl : model.parameters)
      if (decl.name == o.name)
        if (std::string e = RangeError(decl, model.name, it->second); !e.empty())
          throw Error("--set " + o.text + ": " + e + " (declared at " + declared_where[o.name] +
                      ")");
  }
  entry->parameters = params;
  // Copies with their own values: over the entry's, before --set (which
  // sets every copy of the model).
  for (const Field& element : loader::ListElements(*file_, f.Get("instances"), "instances")) {
    Fields inst(*file_, element, "an instances entry");
    inst.Expect({"index", "parameters"});
    const int64_t index = world_values.Integer(inst.Require("index"), 0, kMaxCount - 1);
    if (entry->own_copy_of.contains(index))
      file_->Fail(inst.Get("index").mark,
                  "copy " + std::to_string(index) + " is given twice in 'instances'");
    auto own = std::make_shared<ParameterSet>(*params);
    apply(inst.Require("parameters"), own.get());
    for (Override& o : overrides_)
      if (o.model == model.name) (*own)[o.name] = (*params)[o.name];
    entry->own_copy_of.emplace(index, entry->own_copies.size());
    entry->own_copies.push_back({index, element, std::move(own), std::nullopt, {}, {}});
  }

  // The model's objects, in a scope where its parameters shadow the world's.
  const ValueReader model_values(model.file, &expressions_, {&parameters_, params.get()});
  entry->spec = loader::ResolveModel(model, model_values, &scripts_, &meshes_, world_registry_);
  entry->footprint = loader::ComputeFootprint(entry->spec);
  if (f.Has("scale")) {
    // Every length of the model scales, so its footprint does too.
    static constexpr NumberRule kScale{"a number from 0.001 to 1000", 1e-3, 1e3};
    entry->scale = world_values.Number(f.Get("scale"), kScale);
    entry->footprint.radius *= entry->scale;
    entry->footprint.bottom *= entry->scale;
  }
  entry->ik_groups = loader::ReadIkGroups(model, model_values);
  // A copy with values of its own gets objects of its own: every value of
  // the model that uses a parameter (a sensor's range, a size, a limit, a
  // mass, an IK setting) takes the copy's value.
  for (EntryPlan::OwnCopy& own : entry->own_copies) {
    if (*own.parameters == *params) continue;  // nothing of its own: duplicated as the others
    const ValueReader own_values(model.file, &expressions_, {&parameters_, own.parameters.get()});
    try {
      own.spec = loader::ResolveModel(model, own_values, &scripts_, &meshes_, world_registry_);
      own.ik_groups = loader::ReadIkGroups(model, own_values);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (with the parameters of copy " +
                  std::to_string(own.index) + " given at " + file_->Where(own.field.mark) + ")");
    }
    own.footprint = loader::ComputeFootprint(*own.spec);
    own.footprint.radius *= entry->scale;
    own.footprint.bottom *= entry->scale;
  }

  // Placement: distributed copies or one placed copy.
  if (f.Has("distribute")) {
    for (const char* key : {"position", "heading_deg", "orientation_deg"})
      if (f.Has(key))
        file_->Fail(f.Get(key).key_mark,
                    "'" + std::string(key) +
                        "' places a single copy; it cannot be combined with "
                        "'distribute' (use distribute.heading_deg for a fixed heading)");
    entry->distribute = true;
    entry->count_field = f.Require("count");
    entry->count = world_values.Integer(entry->count_field, 0, kMaxCount);
    Fields d(*file_, f.Get("distribute"), "'distribute'");
    d.Expect({"region", "clearance", "heading_deg"});
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
    const double r = entry->MaxFootprintRadius();
    if (entry->count > 0 && (entry->region.max_x - entry->region.min_x < 2 * r ||
                             entry->region.max_y - entry->region.min_y < 2 * r))
      file_->Fail(entry->count_field.mark, "the region is too small for one " + model.name +
                                               " (footprint radius " + loader::FormatNumber(r) +
                                               " m)");
  } else {
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
  for (const EntryPlan::OwnCopy& own : entry->own_copies)
    if (own.index >= entry->count)
      file_->Fail(Fields(*file_, own.field, "an instances entry").Get("index").mark,
                  "'index' must be below the entry's count (" + std::to_string(entry->count) +
                      "): copies are numbered from 0");
}

void WorldLoader::PlaceEntries() {
  // Fixed copies first, so distributed ones keep clear of them wherever they are listed.
  for (EntryPlan& e : entries_) {
    if (e.distribute) continue;
    const Pose& X = e.fixed_pose;
    const double radius = e.FootprintOf(0).radius;
    if (!placer_->IsFree(X.p.x, X.p.y, radius, 0))
      file_->Fail(e.position_field.mark,
                  "this " + e.model->name + " at [" + loader::FormatNumber(X.p.x) + ", " +
                      loader::FormatNumber(X.p.y) +
                      "] overlaps a wall, an obstacle or another placed copy");
    placer_->AddBody(X.p.x, X.p.y, radius);
  }
  uint64_t stream = 0;
  for (EntryPlan& e : entries_) {
    if (!e.distribute) continue;
    if (e.own_copies.empty()) {
      e.placements = placer_->Distribute(e.region, e.count, e.footprint.radius, e.clearance,
                                         stream++, e.heading);
    } else {
      // Copies whose own values change their size have footprints of their own.
      e.placements = placer_->Distribute(
          e.region, e.count, [&e](int64_t k) { return e.FootprintOf(k).radius; },
          e.MaxFootprintRadius(), e.clearance, stream++, e.heading);
    }
    if (static_cast<int64_t>(e.placements.size()) < e.count)
      file_->Fail(e.count_field.mark,
                  "cannot place " + std::to_string(e.count) + " " + e.model->name + " copies in " +
                      e.region_text + " without overlap (placed " +
                      std::to_string(e.placements.size()) + "); enlarge the " +
                      (e.region_text == "the arena" ? "arena" : "region") + " or reduce count");
  }
}

void WorldLoader::BuildCopies(World* world) {
  Scene& scene = world->scene();
  for (EntryPlan& e : entries_) {
    std::vector<Pose> poses;
    if (!e.distribute) {
      poses.push_back(e.fixed_pose);
    } else {
      for (size_t k = 0; k < e.placements.size(); ++k) {
        const Placement2& p = e.placements[k];
        poses.push_back(
            {{p.x, p.y, -e.FootprintOf(static_cast<int64_t>(k)).bottom}, Quat::FromYaw(p.yaw)});
      }
    }
    if (poses.empty()) continue;
    // Copies built from their own description: the entry's first copy, and
    // each copy with values of its own. The others are duplicated from the
    // entry's first copy (rows copied, scripts and mesh assets shared); each
    // copy is a robot named model#index.
    const std::string& name = e.model->name;
    size_t duplicates = poses.size();
    for (const EntryPlan::OwnCopy& own : e.own_copies) duplicates -= own.spec.has_value();
    ScaledMeshes scaled_meshes;
    auto build = [&](const ObjectSpec& spec, const std::vector<loader::IkGroupDef>& ik_groups,
                     std::optional<size_t> reserve) {
      const ObjectId root = loader::AddToScene(spec, {}, &scene);
      // Scaled once, before duplication: copies share the scaled mesh assets
      // (copies with objects of their own too).
      if (e.scale != 1) {
        scene.ScaleSubtree(root, e.scale);
        if (!e.own_copies.empty()) ShareScaledMeshes(spec, root, &scene, &scaled_meshes);
      }
      if (reserve) scene.ReserveForCopies(root, *reserve);
      const int instance = scene.MakeModelInstance(
          root, name, name + "#" + std::to_string(scene.instances().size()));
      // IK groups of this copy; duplicates get theirs from the "ik" module.
      loader::AddIkGroups(*e.model, ik_groups, spec, root, world);
      return std::pair(root, instance);
    };
    ObjectId first;  // the entry's first copy built from its own description
    for (size_t k = 0; k < poses.size(); ++k) {
      const EntryPlan::OwnCopy* own = e.FindOwnCopy(static_cast<int64_t>(k));
      ObjectId root;
      int instance;
      if (own && own->spec) {
        std::tie(root, instance) = build(*own->spec, own->ik_groups, std::nullopt);
      } else if (first.IsNull()) {
        std::tie(root, instance) = build(e.spec, e.ik_groups, duplicates - 1);
        first = root;
      } else {
        root = scene.DuplicateSubtree(first, {});
        instance = scene.instance_of(root);
      }
      scene.set_name(root, scene.instance(instance).name);
      // The root's pose in the model frame (scaled with the copy).
      Pose X_MR = e.SpecOf(static_cast<int64_t>(k)).X_PO;
      X_MR.p = X_MR.p * e.scale;
      scene.SetWorldPose(root, poses[k] * X_MR);
      world->SetInstanceParameters(instance, own ? own->parameters : e.parameters);
    }
  }
}

std::vector<ModelSummary> WorldLoader::Summarize() const {
  std::vector<ModelSummary> out;
  for (const EntryPlan& e : entries_) {
    ModelSummary m;
    m.name = e.model->name;
    m.file = e.model->file.name();
    m.count = e.count;
    const ValueReader defaults(e.model->file, &expressions_, {&parameters_, nullptr});
    for (const auto& decl : e.model->parameters) {
      ParameterSummary p;
      p.name = decl.name;
      p.value = ShowParamValue(e.parameters->at(decl.name));
      p.default_value = ShowParamValue(defaults.Resolve(decl.default_value));
      p.unit = decl.unit;
      p.description = decl.description;
      if (decl.has_range)
        p.range =
            "[" + loader::FormatNumber(decl.min) + ", " + loader::FormatNumber(decl.max) + "]";
      m.parameters.push_back(std::move(p));
    }
    for (const EntryPlan::OwnCopy& own : e.own_copies) {
      std::string text;
      for (const auto& [name, value] : *own.parameters)
        if (!(value == e.parameters->at(name)))
          text += (text.empty() ? "" : ", ") + name + "=" + ShowParamValue(value);
      m.instances.emplace_back(own.index, text);
    }
    std::vector<std::pair<std::string, std::string>> scripts;
    CollectScripts(e.spec, ":", &scripts);
    for (const EntryPlan::OwnCopy& own : e.own_copies)  // a copy's own values may name others
      if (own.spec) {
        std::vector<std::pair<std::string, std::string>> own_scripts;
        CollectScripts(*own.spec, ":", &own_scripts);
        for (auto& script : own_scripts)
          if (std::none_of(scripts.begin(), scripts.end(),
                           [&](const auto& s) { return s.first == script.first; }))
            scripts.push_back(std::move(script));
      }
    for (const auto& [file, where] : scripts) m.scripts.push_back(file + " " + where);
    m.scale = e.scale;
    m.ik_groups = static_cast<int>(e.ik_groups.size());
    out.push_back(std::move(m));
  }
  return out;
}

// --- Metrics -------------------------------------------------------------------------------

std::vector<SwarmMetricSpec> WorldLoader::ReadMetrics(const Fields& top, World* world) {
  std::vector<SwarmMetricSpec> out;
  const ValueReader values = WorldValues();
  std::vector<std::string> known;  // the registered metric modules
  for (const ModuleDescriptor* metric : world->registry().ModulesOfKind("metric"))
    known.push_back(metric->info.name);
  for (const Field& element : loader::ListElements(*file_, top.Get("metrics"), "metrics")) {
    SwarmMetricSpec spec;
    Field name_field = element;
    if (element.node.IsMap()) {
      Fields f(*file_, element, "a metric");
      f.Expect({"name", "every"});
      name_field = f.Require("name");
      if (f.Has("every"))
        spec.every_steps = static_cast<int>(values.Integer(f.Get("every"), 1, 1 << 30));
    }
    name_field.name = "name";
    spec.name = values.String(name_field);
    if (std::find(known.begin(), known.end(), spec.name) == known.end())
      file_->Fail(name_field.mark,
                  "unknown metric '" + spec.name + "'" + loader::Suggest(spec.name, known));
    try {
      world->AddModule(spec.name, &spec.every_steps);
    } catch (const Error& e) {
      file_->Fail(name_field.mark, e.what());
    }
    out.push_back(spec);
  }
  return out;
}

}  // namespace

LoadedWorld LoadWorld(const fs::path& file, const LoadOptions& options,
                      const ModuleRegistry& registry) {
  WorldLoader loader(file, options, registry);
  try {
    return loader.Load();
  } catch (const Error&) {
    throw;
  } catch (const YAML::Exception& e) {
    // A yaml-cpp conversion the checks above missed: still a message, never a crash.
    throw Error(loader::DisplayPath(file) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw Error(loader::DisplayPath(file) + ": out of memory while loading the world");
  }
}

}  // namespace swarmsim
