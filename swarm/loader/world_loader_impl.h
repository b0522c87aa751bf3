// Internal to the world loader (swarm/loader), not for use outside it: the
// WorldLoader class behind LoadWorld and the types it works with. Its members
// are defined by topic: world_loader.cc (the world file's parameters, plugins,
// simulation, arena, obstacles, modules' sections) and world_entries.cc (the
// `models:` entries: their parameters, objects and placement, and the copies
// built from them).
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swarm/loader/mesh.h"
#include "swarm/loader/model.h"
#include "swarm/loader/placement.h"
#include "swarm/loader/values.h"
#include "swarm/loader/world_loader.h"
#include "swarm/loader/yaml.h"

namespace swarmsim {
class ModelSectionData;
class ObjectReader;
class ModuleRegistry;
struct EnvironmentFormatDescriptor;
}  // namespace swarmsim

namespace swarmsim::loader {

inline constexpr int64_t kMaxCount = 1000000;  // copies per models entry

// A models entry's keys: the loader's own, with the registered model-file
// sections' (framework/model_section.h: an imported robot's `ik_groups`)
// after `scripts`.
std::vector<std::string> EntryKeys(const ModuleRegistry& registry);
// The registered model-file sections' keys, in registration order.
std::vector<std::string> ModelSectionKeys(const ModuleRegistry& registry);
// What each registered model-file section reads from `top` (a model file's
// top level or a models entry), in registration order (null: absent).
std::vector<std::shared_ptr<const ModelSectionData>> ReadModelSections(
    const ModuleRegistry& registry, const ObjectReader& top, const std::string& model);

// One --set, split into its target.
struct Override {
  std::string text;   // "--set name=value" (LoadOptions::override_option), for messages
  std::string model;  // "" for a world parameter
  std::string name;
  std::string value;
  bool used = false;
};

// A --set value with the type of the parameter it replaces: a string
// parameter takes the text as is; a number or boolean must read as one.
ParamValue CoerceOverride(const Override& o, const ParamValue& declared,
                          const std::string& declared_where);

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
  Field region_field;       // distribute.region as {min, max} (absent: the arena)
  double clearance = 0;
  std::optional<double> heading;
  // distribute.order: spatial: copies numbered along a space-filling curve
  // (SortAlongCurve) instead of in the order they were drawn.
  bool spatial_order = false;
  bool order_given = false;  // distribute: {order: ...} written (no hint either way)
  // distribute.lattice: copies on a square or hexagonal lattice instead of at random.
  struct LatticePlan {
    double spacing = 0;  // m
    bool hexagonal = false;
    int64_t columns = 0;
    Field field;  // for messages
  };
  std::optional<LatticePlan> lattice;
  std::vector<Placement2> placements;
  // What the model file's sections (framework/model_section.h) read, one
  // per registered section (null: the key is absent), and what the entry's
  // own keys of the same name read (in the world file, with its values).
  std::vector<std::shared_ptr<const ModelSectionData>> sections;
  std::vector<std::shared_ptr<const ModelSectionData>> entry_sections;
  PythonController python;  // python_controller: (file empty: none)
  // native_controller: (null: none); the plugin's controller every copy runs.
  const PluginControllerType* native = nullptr;
  bool native_replaces_scripts = false;  // the model's Lua scripts were dropped for it
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
    std::vector<std::shared_ptr<const ModelSectionData>> sections;  // read with its values
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

class WorldLoader {
 public:
  WorldLoader(const std::filesystem::path& file, const LoadOptions& options,
              const ModuleRegistry& registry)
      : path_(file), options_(options), registry_(registry) {
    meshes_.set_load_hooks(options_.check_stop, options_.note);
  }

  LoadedWorld Load();
  // After Load: each distributed robot's root pose as a load with `seed`
  // places it (robot index, world pose), robots in index order
  // (LoadedWorld::placement). Throws swarmsim::Error as Load does when the
  // copies do not fit.
  std::vector<std::pair<int, Pose>> Placements(uint64_t seed);

 private:
  // A model's declared parameters, for the messages about values given for them.
  struct DeclaredParameters {
    std::map<std::string, std::string> where;  // name -> where its default is given
    std::vector<std::string> names;            // in declaration order
  };

  // The world file (world_loader.cc).
  void ReadParameters(const Fields& top);
  std::shared_ptr<const ModuleRegistry> LoadPlugins(const Fields& top);
  bool IsTrustedPluginLocation(const std::filesystem::path& canonical) const;
  void ReadModelEntries(const Fields& top);
  void CheckOverrides();
  WorldSettings ReadSimulation(const Fields& top, std::optional<int64_t>* steps);
  void BuildArena(const Fields& top, World* world);
  void BuildObstacles(const Fields& top, World* world);
  void AddObstacleFootprint(const ShapeData& shape, const Pose& X_WO);
  void ReadSections(const Fields& top, World* world);
  std::vector<std::string> MetricNames(const World& world) const;
  int64_t ReadRecord(const Fields& top) const;

  // The models entries (world_entries.cc), in the order Load runs them.
  void ResolveEntry(EntryPlan* entry);
  void ResolveEntryParameters(const Fields& f, const ValueReader& world_values,
                              DeclaredParameters* declared, EntryPlan* entry);
  std::shared_ptr<ParameterSet> ModelParameters(const ModelFile& model, const Field& entry_values,
                                                const Field& own_values,
                                                const ValueReader& world_values,
                                                const DeclaredParameters& declared);
  void ReadOwnCopies(const Fields& f, const ValueReader& world_values, DeclaredParameters* declared,
                     EntryPlan* entry);
  void ResolveObjects(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void ExtendObjects(const Fields& f, const ValueReader& world_values, const EntryPlan& entry,
                     ObjectSpec* spec);
  void ReadPackagePath(const Fields& top);
  void ResolvePlacement(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void ResolvePythonController(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void ResolveNativeController(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void ReadDistribution(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void ReadLattice(const Fields& d, const ValueReader& world_values, double footprint_radius,
                   EntryPlan* entry);
  void ReadSinglePosition(const Fields& f, const ValueReader& world_values, EntryPlan* entry);
  void KeepPlacementClearOfTheMap(std::vector<std::string>* warnings);
  // The tallest copy's height (footprint top - bottom, scaled), m: the band
  // from the ground up that placement keeps clear.
  double CopiesHeight() const;
  // Large swarms left on the defaults that are slow at their size (a Lua
  // state per robot, copies numbered at random): a line each saying which
  // setting to write.
  void AddLargeSwarmHints(const WorldSettings& settings, std::vector<std::string>* warnings) const;
  void AddPlaneWheelHints(const WorldSettings& settings, std::vector<std::string>* warnings) const;
  void PlaceEntries(std::vector<std::string>* warnings);
  void BuildCopies(World* world);
  std::vector<ModelSummary> Summarize() const;

  const ModelFile& LoadModel(const Field& field, const std::string& text);
  ValueReader WorldValues() const {
    return ValueReader(*file_, &expressions_, {&parameters_, nullptr});
  }

  std::filesystem::path path_;
  const LoadOptions options_;  // a copy: the loader outlives LoadWorld (Placements)
  const ModuleRegistry& registry_;
  const ModuleRegistry* world_registry_ = nullptr;  // registry_ plus the world's plugins
  std::unique_ptr<YamlFile> file_;
  mutable Expressions expressions_;
  ScriptCache scripts_;
  MeshCache meshes_;  // each mesh file read once per world
  std::vector<Override> overrides_;
  ParameterSet parameters_;
  std::map<std::string, Field> parameter_fields_;  // where each world parameter is set
  std::map<std::filesystem::path, std::unique_ptr<ModelFile>> models_;
  std::vector<EntryPlan> entries_;
  std::optional<Region2> arena_;
  Field environment_field_;                            // `environment:` (absent: none)
  std::shared_ptr<const EnvironmentMap> environment_;  // the map it names, or null
  const EnvironmentFormatDescriptor* environment_format_ = nullptr;  // the format that read it
  bool ground_plane_ = false;  // the physics has a ground at z = 0 (ode): no copy below it
  std::unique_ptr<Placer> placer_;
  // Placements: the placer before the entries were placed, and the robot
  // each copy became (entries in order, copies in order).
  std::unique_ptr<Placer> unplaced_;
  std::vector<int> copy_instances_;
  std::vector<std::filesystem::path> package_path_;  // the world's, then --package-path
  std::vector<std::string> warnings_;                // found before the World exists
  bool robots_per_lua_state_given_ = false;          // simulation.robots_per_lua_state written
  bool physics_partitions_given_ = false;            // simulation.physics_partitions written
};

}  // namespace swarmsim::loader
