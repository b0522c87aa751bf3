// WorldLoader: placing the `models:` entries' copies together (fixed ones
// first, then each distributed entry's, clear of walls, obstacles and the
// environment map) and building them into the scene, with their modules'
// model sections; the placements again for another seed (reset), and the
// entries' summaries (describe). world_entries.cc resolves the entries.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/memory_forecast.h"
#include "framework/model_section.h"
#include "framework/plugin_controllers.h"
#include "framework/prefault.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "modules/dynamics/height_range.h"
#include "swarm/loader/world_loader_impl.h"

namespace swarmsim::loader {

namespace {

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

// The paths of the objects below `spec` ("a", "a/b", ...), in model order.
void CollectPaths(const ObjectSpec& spec, const std::string& prefix,
                  std::vector<std::string>* out) {
  for (const ObjectSpec& child : spec.children) {
    const std::string path = prefix.empty() ? child.name : prefix + "/" + child.name;
    out->push_back(path);
    CollectPaths(child, path, out);
  }
}

// The model's sections (and the entry's own) applied to a copy built from
// `spec` at `root`, in registration order.
void ApplyModelSections(const ModuleRegistry& registry,
                        const std::vector<std::shared_ptr<const ModelSectionData>>& sections,
                        const std::vector<std::shared_ptr<const ModelSectionData>>& entry_sections,
                        const ObjectSpec& spec, ObjectId root, const std::string& model,
                        World* world) {
  std::vector<std::string> paths;
  const auto& descriptors = registry.model_sections();
  for (size_t i = 0; i < descriptors.size(); ++i)
    for (const auto* list : {&sections, &entry_sections}) {
      if (i >= list->size() || !(*list)[i]) continue;
      if (paths.empty()) CollectPaths(spec, "", &paths);
      descriptors[i]->apply(*(*list)[i], ModelCopy{root, model, spec.name, paths}, world);
    }
}

// Points the mesh shapes of the copy at `id` (built from `spec`, then scaled)
// at the assets an earlier copy of the entry was scaled to, so that copies
// built from their own description share them as duplicates do.
void ShareScaledMeshes(const ObjectSpec& spec, ObjectId id, Scene* scene, ScaledMeshes* scaled) {
  const ShapeData* shape = spec.AsShape();
  if (shape != nullptr && shape->mesh) {
    const auto [it, added] = scaled->emplace(shape->mesh.get(), scene->shape(id).mesh);
    if (!added) scene->mutable_shape(id).mesh = it->second;
  }
  const std::vector<ObjectId> children = scene->children(id);
  for (size_t i = 0; i < spec.children.size() && i < children.size(); ++i)
    ShareScaledMeshes(spec.children[i], children[i], scene, scaled);
}

}  // namespace

// --- Placing and building the copies ------------------------------------------------------

double WorldLoader::CopiesHeight() const {
  double height = 0;
  for (const EntryPlan& e : entries_) {
    height = std::max(height, e.footprint.top - e.footprint.bottom);
    for (const EntryPlan::OwnCopy& own : e.own_copies)
      if (own.spec) height = std::max(height, own.footprint.top - own.footprint.bottom);
  }
  return height;
}

// The obstacles and the environment map's voxels that a copy standing on
// the ground would meet (those reaching into the band from the ground to
// the tallest copy's top, less 1 mm at either end: a floor whose top is at
// z = 0 is not one, nor a shelf above the robots), the voxels projected to
// the plane by the map's format (its occupied_plane query): placement keeps
// copies clear of them.
void WorldLoader::KeepPlacementClearOfTheMap(std::vector<std::string>* warnings) {
  if (entries_.empty()) return;
  // Obstacles too: those reaching into the same band (a box hanging 0.5 m
  // up refused a 2 cm robot under it as "overlapping").
  placer_->KeepObstaclesReaching(0, CopiesHeight(), dynamics::kHeightOverlap);
  if (!environment_) return;
  if (!environment_format_ || !environment_format_->occupied_plane) {
    // A format that cannot say which cells it fills: robots are placed as
    // if it were not there, which the user is told.
    warnings->push_back(
        "the environment map's format" +
        std::string(environment_format_ ? " '" + environment_format_->key + "'" : std::string()) +
        " cannot list its occupied cells: placement does not keep robots clear "
        "of the map");
    return;
  }
  const double height = CopiesHeight();
  constexpr double kOverlap = dynamics::kHeightOverlap;  // m, as the physics backends' rule
  try {
    placer_->SetMapCells(
        environment_format_->occupied_plane(*environment_, kOverlap, height - kOverlap));
  } catch (const Error& e) {
    file_->Fail(environment_field_.mark, e.what());
  }
}

void WorldLoader::PlaceEntries(std::vector<std::string>* warnings) {
  const auto arena_text = [this] {
    return "(the arena is [" + loader::FormatNumber(arena_->min_x) + ", " +
           loader::FormatNumber(arena_->min_y) + "] to [" + loader::FormatNumber(arena_->max_x) +
           ", " + loader::FormatNumber(arena_->max_y) + "])";
  };
  // Fixed copies first, so distributed ones keep clear of them wherever they are listed.
  for (EntryPlan& e : entries_) {
    if (e.distribute) continue;
    const Pose& X = e.fixed_pose;
    const double radius = e.FootprintOf(0).radius;
    // Upright and below ODE's ground: the contacts throw it up out of it (a
    // warning: a published robot's base may reach a little below its origin).
    const double lowest = X.p.z + e.FootprintOf(0).bottom;
    if (ground_plane_ && std::abs(X.q.x) < 1e-9 && std::abs(X.q.y) < 1e-9 && lowest < -1e-3)
      warnings->push_back(file_->Where(e.position_field.mark) + ": this " + e.model->name +
                          " at z = " + loader::FormatNumber(X.p.z) + " reaches " +
                          loader::FormatNumber(-lowest) +
                          " m below the ground (z = 0 under physics: ode): the contacts will "
                          "throw it up; give z >= " +
                          loader::FormatNumber(-e.FootprintOf(0).bottom) +
                          ", or [x, y] alone to stand it on the ground");
    if (!placer_->IsFree(X.p.x, X.p.y, radius, 0))
      file_->Fail(e.position_field.mark,
                  "this " + e.model->name + " at [" + loader::FormatNumber(X.p.x) + ", " +
                      loader::FormatNumber(X.p.y) +
                      "] overlaps a wall, an obstacle, the map or another placed copy (its "
                      "footprint: a disc of radius " +
                      loader::FormatNumber(radius) +
                      " m about [x, y] that holds every shape of the model)");
    // Clear of the walls and outside them: allowed (an observer, a beacon),
    // but seldom meant (a coordinate of another, larger arena).
    if (arena_ && (X.p.x < arena_->min_x || X.p.x > arena_->max_x || X.p.y < arena_->min_y ||
                   X.p.y > arena_->max_y))
      warnings->push_back(file_->Where(e.position_field.mark) + ": this " + e.model->name +
                          " at [" + loader::FormatNumber(X.p.x) + ", " +
                          loader::FormatNumber(X.p.y) + "] stands outside the arena's walls " +
                          arena_text());
    placer_->AddBody(X.p.x, X.p.y, radius);
  }
  // Copies drawn at random (a million take seconds): the stop signals are
  // heard and the progress told every 4,096.
  int64_t to_place = 0, placed = 0;
  for (const EntryPlan& e : entries_)
    if (e.distribute && !e.lattice) to_place += e.count;
  placer_->set_every_4096([this, &placed, to_place](int64_t k) {
    if (options_.check_stop) options_.check_stop();
    if (options_.progress)
      options_.progress(LoadOptions::LoadStage::kPlacing, placed + k, to_place);
  });
  struct Forget {  // the call refers to this frame's counts
    Placer* placer;
    ~Forget() { placer->set_every_4096({}); }
  } forget{placer_.get()};
  uint64_t stream = 0;
  for (EntryPlan& e : entries_) {
    if (!e.distribute) continue;
    // A region reaching past the walls: the copies drawn there stand
    // outside them (as a fixed copy outside, allowed and seldom meant).
    const Region2& r = e.region;
    if (arena_ && e.region_field.present() &&
        (r.min_x < arena_->min_x || r.max_x > arena_->max_x || r.min_y < arena_->min_y ||
         r.max_y > arena_->max_y))
      warnings->push_back(file_->Where(e.region_field.mark) + ": " + e.region_text +
                          " reaches outside the arena's walls " + arena_text() + ": " +
                          e.model->name + " copies drawn there stand outside them");
    if (e.lattice) {
      int64_t bad = -1;
      e.placements =
          placer_->Lattice(e.region, e.count, e.MaxFootprintRadius(), e.lattice->spacing,
                           e.lattice->hexagonal, e.lattice->columns, stream++, e.heading, &bad);
      if (bad >= 0)
        file_->Fail(e.lattice->field.mark,
                    "the lattice does not fit: " + e.model->name + " copy " + std::to_string(bad) +
                        " of " + std::to_string(e.count) + " would " + "leave " + e.region_text +
                        " or overlap a wall, an obstacle, the map or another placed copy; "
                        "enlarge the region, or reduce 'spacing' or 'count'");
      continue;
    }
    if (e.own_copies.empty()) {
      e.placements = placer_->Distribute(e.region, e.count, e.footprint.radius, e.clearance,
                                         stream++, e.heading);
      // order: spatial: numbered along a space-filling curve, so that
      // neighbours are near in memory (never with `instances`: the loader
      // refuses the two together).
      if (e.spatial_order) SortAlongCurve(&e.placements, 2 * e.footprint.radius + e.clearance);
    } else {
      // Copies whose own values change their size have footprints of their own.
      e.placements = placer_->Distribute(
          e.region, e.count, [&e](int64_t k) { return e.FootprintOf(k).radius; },
          e.MaxFootprintRadius(), e.clearance, stream++, e.heading);
    }
    placed += static_cast<int64_t>(e.placements.size());
    if (static_cast<int64_t>(e.placements.size()) < e.count)
      file_->Fail(e.count_field.mark,
                  "cannot place " + GroupThousands(e.count) + " " + e.model->name + " copies in " +
                      e.region_text + " without overlap (placed " +
                      GroupThousands(static_cast<int64_t>(e.placements.size())) +
                      "); enlarge the " + (e.region_text == "the arena" ? "arena" : "region") +
                      " or reduce count");
  }
  if (options_.progress && to_place > 0)
    options_.progress(LoadOptions::LoadStage::kPlacing, placed, to_place);
}

void WorldLoader::BuildCopies(World* world) {
  Scene& scene = world->scene();
  int64_t total = 0, built = 0;  // copies, for options_.progress
  for (const EntryPlan& e : entries_)
    total += e.distribute ? static_cast<int64_t>(e.placements.size()) : 1;
  MemoryForecast forecast("robot copies", total, options_.max_memory);
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
    auto build = [&](const ObjectSpec& spec,
                     const std::vector<std::shared_ptr<const ModelSectionData>>& sections,
                     std::optional<size_t> reserve) {
      const ObjectId root = loader::AddToScene(spec, {}, &scene);
      // Scaled once, before duplication: copies share the scaled mesh assets
      // (copies with objects of their own too).
      if (e.scale != 1) {
        scene.ScaleSubtree(root, e.scale);
        if (!e.own_copies.empty()) ShareScaledMeshes(spec, root, &scene, &scaled_meshes);
      }
      if (reserve) {
        // The copies' rows are written into pages populated on every thread
        // first (the kernel zeroing them was most of a large world's copies).
        Prefault prefault;
        try {
          scene.ReserveForCopies(root, *reserve, &prefault);
          world->ReserveRobots(scene.instances().size() + 1 + *reserve, &prefault);
        } catch (const std::bad_alloc&) {
          throw Error(forecast.ReserveFailed(prefault.bytes()));
        }
        // Populated at once, so checked at once: a world whose arrays alone
        // do not fit is refused here with a message, not ended by the
        // kernel's out-of-memory killer while they are populated.
        if (std::string refusal = forecast.Reserved(prefault.bytes()); !refusal.empty())
          throw Error(refusal);
        // A stop signal meanwhile: the rest is left, and the check after
        // throws (10 GiB for a million robots take seconds on cold memory).
        std::atomic<bool> stopped{false};  // (asked on every thread)
        // Progress told on this thread as it takes a chunk: Run asks before
        // each chunk of 8 MiB.
        const int64_t to_populate = static_cast<int64_t>(prefault.bytes());
        std::atomic<int64_t> chunks{0};
        const std::thread::id loading = std::this_thread::get_id();
        prefault.Run(world->scheduler(), [&, this] {
          const int64_t begun = chunks.fetch_add(1, std::memory_order_relaxed);
          if (options_.progress && to_populate > 0 && std::this_thread::get_id() == loading)
            options_.progress(LoadOptions::LoadStage::kPopulating,
                              std::min(begun * (int64_t{8} << 20), to_populate), to_populate);
          if (!options_.check_stop || stopped.load()) return stopped.load();
          try {
            options_.check_stop();
          } catch (const Error&) {
            stopped.store(true);
          }
          return stopped.load();
        });
        if (stopped.load()) options_.check_stop();
        if (options_.progress && to_populate > 0)
          options_.progress(LoadOptions::LoadStage::kPopulating, to_populate, to_populate);
      }
      const int instance = scene.MakeModelInstance(
          root, name, name + "#" + std::to_string(scene.instances().size()));
      // The model's sections for this copy (its IK groups); duplicates get
      // theirs from the modules, which follow copies.
      ApplyModelSections(registry_, sections, e.entry_sections, spec, root, name, world);
      return std::pair(root, instance);
    };
    ObjectId first;  // the entry's first copy built from its own description
    // The root's pose in the model frame (scaled with the copy).
    const auto root_pose = [&](size_t k) {
      Pose X_MR = e.SpecOf(static_cast<int64_t>(k)).X_PO;
      X_MR.p = X_MR.p * e.scale;
      return poses[k] * X_MR;
    };
    // What each copy gets once it exists: its name, values and controller.
    const auto finish = [&](ObjectId root, int instance, const EntryPlan::OwnCopy* own) {
      scene.set_name(root, scene.instance(instance).name);
      copy_instances_.push_back(instance);
      world->SetInstanceParameters(instance, own ? own->parameters : e.parameters);
      if (e.native != nullptr)
        world->SetNativeController(instance, e.native, e.native_replaces_scripts);
    };
    // Where a batch of duplicates ends: a count the progress or the memory
    // forecast looks at.
    const auto stop_at = [&forecast](int64_t b) {
      return b % 256 == 0 || (forecast.stride() > 0 && b % forecast.stride() == 0);
    };
    std::vector<Pose> batch;
    for (size_t k = 0; k < poses.size();) {
      if (options_.check_stop && built % 256 == 0) options_.check_stop();
      if (options_.progress && built % 256 == 0)
        options_.progress(LoadOptions::LoadStage::kBuilding, built, total);
      if (std::string refusal = forecast.Built(built); !refusal.empty()) throw Error(refusal);
      const EntryPlan::OwnCopy* own = e.FindOwnCopy(static_cast<int64_t>(k));
      if ((own && own->spec) || first.IsNull()) {
        ++built;
        ObjectId root;
        int instance;
        if (own && own->spec) {
          std::tie(root, instance) = build(*own->spec, own->sections, std::nullopt);
        } else {
          std::tie(root, instance) = build(e.spec, e.sections, duplicates - 1);
          first = root;
        }
        scene.SetWorldPose(root, root_pose(k));
        finish(root, instance, own);
        ++k;
        continue;
      }
      // Duplicates of the first copy, built together (on every thread) up to
      // the next copy of its own, progress report or memory checkpoint.
      size_t end = k + 1;
      while (end < poses.size() && !stop_at(built + static_cast<int64_t>(end - k))) {
        const EntryPlan::OwnCopy* next = e.FindOwnCopy(static_cast<int64_t>(end));
        if (next && next->spec) break;
        ++end;
      }
      batch.clear();
      for (size_t j = k; j < end; ++j) batch.push_back(root_pose(j));
      const std::vector<ObjectId> roots = scene.DuplicateSubtrees(first, batch, world->scheduler());
      for (size_t j = k; j < end; ++j) {
        const ObjectId root = roots[j - k];
        finish(root, scene.instance_of(root), e.FindOwnCopy(static_cast<int64_t>(j)));
      }
      built += static_cast<int64_t>(end - k);
      k = end;
    }
  }
  if (options_.progress) options_.progress(LoadOptions::LoadStage::kBuilding, built, total);
}

std::vector<std::pair<int, Pose>> WorldLoader::Placements(uint64_t seed) {
  placer_ = std::make_unique<Placer>(unplaced_->WithSeed(seed));
  std::vector<std::string> said_at_load;  // the load gave these warnings already
  PlaceEntries(&said_at_load);
  // The root poses as BuildCopies sets them.
  std::vector<std::pair<int, Pose>> out;
  size_t copy = 0;
  for (const EntryPlan& e : entries_) {
    const size_t copies = e.distribute ? e.placements.size() : 1;
    for (size_t k = 0; k < copies; ++k, ++copy) {
      if (!e.distribute) continue;
      const Placement2& p = e.placements[k];
      const Pose X_WM{{p.x, p.y, -e.FootprintOf(static_cast<int64_t>(k)).bottom},
                      Quat::FromYaw(p.yaw)};
      Pose X_MR = e.SpecOf(static_cast<int64_t>(k)).X_PO;
      X_MR.p = X_MR.p * e.scale;
      out.emplace_back(copy_instances_.at(copy), X_WM * X_MR);
    }
  }
  return out;
}

std::vector<ModelSummary> WorldLoader::Summarize() const {
  std::vector<ModelSummary> out;
  for (const EntryPlan& e : entries_) {
    ModelSummary m;
    m.name = e.model->name;
    m.file = e.model->file.name();
    m.count = e.count;
    m.spatial_order = e.spatial_order;
    // A default that uses the model's parameters above it: with their values.
    const ValueReader defaults(e.model->file, &expressions_, {&parameters_, e.parameters.get()});
    for (const auto& decl : e.model->parameters) {
      ParameterSummary p;
      p.name = decl.name;
      p.value = ShowParamValue(e.parameters->at(decl.name));
      p.default_value = ShowParamValue(defaults.Resolve(decl.default_value));
      p.unit = decl.unit;
      p.description = decl.description;
      if (decl.has_range) {
        // Appended, not "[" + ...: GCC 12 warns (-Wrestrict, a false positive) on that form here.
        p.range = "[";
        p.range += loader::FormatNumber(decl.min);
        p.range += ", ";
        p.range += loader::FormatNumber(decl.max);
        p.range += "]";
        p.bounds = std::pair(decl.min, decl.max);
      }
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
    for (const auto* sections : {&e.sections, &e.entry_sections})
      for (const auto& section : *sections)
        if (section && !section->Describe().empty()) m.modules.push_back(section->Describe());
    if (e.model->imported) {
      m.file = e.model->imported_file;
      m.imported = e.model->import_summary;
    }
    m.python = e.python;
    if (e.native != nullptr) m.native_controller = e.native->name;
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace swarmsim::loader
