#include "modules/kinematics/ik_model_section.h"

#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/number_rule.h"
#include "framework/suggest.h"
#include "framework/world.h"
#include "modules/kinematics/ik_groups.h"

namespace swarmsim::kinematics {
namespace {

// An object path in the model ("leg1/footTip", "." the root) and where it is written.
struct PathDef {
  std::string path;
  std::string where;  // "file:line:column"
};

struct IkTipDef {
  PathDef tip, target;
  std::optional<PathDef> base;
  uint8_t constraints = kIkPosition;
};

struct IkAvoidDef {
  std::vector<PathDef> links;
  IkAvoidSpec spec;  // obstacle, distance, where
};

struct IkGroupDef {
  std::string where;  // the group's mapping, for messages
  IkGroupSpec spec;   // settings; objects filled in for each copy
  std::vector<IkTipDef> tips;
  std::vector<std::pair<PathDef, double>> weights;  // joint path, weight
  std::vector<IkAvoidDef> avoid;
};

struct IkGroupsData final : ModelSectionData {
  std::vector<IkGroupDef> groups;
  std::string Describe() const override {
    return std::string(kIkModuleName) + " (" + std::to_string(groups.size()) + " IK groups)";
  }
};

const std::vector<std::string> kConstraintNames = {"x",    "y",     "z",        "alpha",
                                                   "beta", "gamma", "position", "pose"};

uint8_t ConstraintBit(const std::string& name) {
  if (name == "position") return kIkPosition;
  if (name == "pose") return kIkPose;
  for (int k = 0; k < 6; ++k)
    if (kConstraintNames[k] == name) return static_cast<uint8_t>(1u << k);
  return 0;
}

// constraints: position | pose | [x, y, z, alpha, beta, gamma] (any subset).
uint8_t ReadConstraints(const ObjectReader& r, const std::string& what) {
  if (!r.IsList("constraints")) return ConstraintBit(r.Choice("constraints", kConstraintNames));
  uint8_t bits = 0;
  for (const auto& e : r.Elements("constraints", "constraints", what, "constraints"))
    bits |= ConstraintBit(e->Choice("constraints", kConstraintNames));
  if (bits == 0)
    r.Fail("constraints", "'constraints' needs at least one of x, y, z, alpha, beta, gamma");
  return bits;
}

PathDef ReadPath(const ObjectReader& r, std::string_view key) {
  return {r.String(key, /*required=*/true), r.Where(key)};
}

IkGroupDef ReadGroup(const ObjectReader& f, const std::string& model,
                     std::set<std::string>* names) {
  f.Expect(std::vector<std::string>{"name", "tips", "mode", "damping", "iterations", "tolerance",
                                    "orientation_tolerance", "max_step", "conditional", "automatic",
                                    "weights", "avoid"});
  IkGroupDef def;
  def.where = f.WhereHere();
  IkGroupSpec& s = def.spec;
  s.name = f.String("name", /*required=*/true);
  if (!names->insert(s.name).second)
    f.Fail("name", "model '" + model + "' already has an IK group '" + s.name + "'");
  if (f.Has("mode"))
    s.mode = f.Choice("mode", {"direct", "targets"}) == "direct" ? IkMode::kDirect
                                                                 : IkMode::kJointTargets;
  if (f.Has("damping")) s.damping = f.Number("damping", kNonNegative);
  if (f.Has("iterations")) s.max_iterations = static_cast<int>(f.Integer("iterations", 1, 10000));
  if (f.Has("tolerance")) s.position_tolerance = f.Number("tolerance", kPositive);
  if (f.Has("orientation_tolerance"))
    s.orientation_tolerance = f.Number("orientation_tolerance", kPositive);
  if (f.Has("max_step")) s.max_step = f.Number("max_step", kPositive);
  if (f.Has("conditional")) s.conditional = f.Bool("conditional");
  if (f.Has("automatic")) s.automatic = f.Bool("automatic");
  f.Require("tips");
  const std::string tip_what = "a tip of IK group '" + s.name + "'";
  for (const auto& t : f.Maps("tips", "tips", tip_what)) {
    t->Expect(std::vector<std::string>{"tip", "target", "base", "constraints"});
    IkTipDef tip;
    tip.tip = ReadPath(*t, "tip");
    tip.target = ReadPath(*t, "target");
    if (t->Has("base")) tip.base = ReadPath(*t, "base");
    if (t->Has("constraints")) tip.constraints = ReadConstraints(*t, tip_what);
    def.tips.push_back(std::move(tip));
  }
  if (def.tips.empty()) f.Fail("tips", "an IK group needs at least one {tip, target} pair");
  if (def.tips.size() > 4) f.Fail("tips", "an IK group has at most 4 tips");
  if (const auto w = f.Map("weights", "the weights of IK group '" + s.name + "'",
                           "a mapping of joint paths to weights")) {
    // The keys are the joints' paths: errors about a path name the key.
    for (const std::string& joint : w->Keys())
      def.weights.emplace_back(PathDef{joint, w->WhereKey(joint)}, w->Number(joint, kNonNegative));
  }
  // avoid: [{links: [paths], collection: PATH | environment, distance: m}]
  for (const auto& a : f.Maps("avoid", "avoid", "an avoid entry of IK group '" + s.name + "'")) {
    a->Expect(std::vector<std::string>{"links", "collection", "distance"});
    IkAvoidDef avoid;
    a->Require("links");
    for (const auto& link : a->Elements("links", "links", "a link", "links"))
      avoid.links.push_back(ReadPath(*link, "links"));
    if (avoid.links.empty()) a->Fail("links", "'links' needs at least one link path");
    avoid.spec.obstacle = a->String("collection", /*required=*/true);
    avoid.spec.where = a->Where("collection");
    if (a->Has("distance")) avoid.spec.distance = a->Number("distance", kPositive);
    def.avoid.push_back(std::move(avoid));
  }
  return def;
}

std::shared_ptr<const ModelSectionData> Read(const ObjectReader& top, const std::string& model) {
  if (!top.Has("ik_groups")) return nullptr;
  auto data = std::make_shared<IkGroupsData>();
  std::set<std::string> names;
  for (const auto& group :
       top.Maps("ik_groups", "IK groups", "an IK group of model '" + model + "'"))
    data->groups.push_back(ReadGroup(*group, model, &names));
  if (data->groups.empty()) return nullptr;
  return data;
}

// Resolves the paths against the copy and adds its groups to the world.
void Apply(const ModelSectionData& section, const ModelCopy& copy, World* world) {
  const auto& data = static_cast<const IkGroupsData&>(section);  // Read made it
  Scene& scene = world->scene();
  IkGroups* module = &IkGroupsOf(world);
  const auto fail = [](const std::string& where, const std::string& message) {
    throw Error(where + ": " + message);
  };
  // A path in the model, from its root: "leg1/footTip" (or "." for the root).
  auto resolve = [&](const PathDef& def) {
    ObjectId id;
    try {
      id = scene.FindObject(def.path == "." ? "." : "./" + def.path, copy.root);
    } catch (const Error& e) {
      fail(def.where, e.what());
    }
    // The root is named after the copy; its name in the file (a URDF's root link) names it too.
    if (id.IsNull() && def.path == copy.root_name) id = copy.root;
    if (id.IsNull()) {
      // A typo in a bare name is nearer the name than its whole path.
      std::vector<std::string> names(copy.paths.begin(), copy.paths.end());
      for (const std::string& path : copy.paths)
        if (const size_t slash = path.rfind('/'); slash != std::string::npos)
          names.push_back(path.substr(slash + 1));
      std::sort(names.begin(), names.end());
      names.erase(std::unique(names.begin(), names.end()), names.end());
      fail(def.where,
           "no object '" + def.path + "' in model '" + copy.model + "'" + Suggest(def.path, names));
    }
    return id;
  };
  for (const IkGroupDef& def : data.groups) {
    IkGroupSpec s = def.spec;
    for (const IkTipDef& t : def.tips) {
      IkTipSpec tip;
      tip.tip = resolve(t.tip);
      tip.target = resolve(t.target);
      if (t.base) tip.base = resolve(*t.base);
      tip.constraints = t.constraints;
      if (scene.type(tip.tip) == ObjectType::kDummy && scene.type(tip.target) == ObjectType::kDummy)
        scene.LinkDummies(tip.tip, tip.target);
      s.tips.push_back(tip);
    }
    for (const auto& [path, weight] : def.weights) {
      const ObjectId joint = resolve(path);
      if (scene.type(joint) != ObjectType::kJoint)
        fail(path.where, "'" + path.path + "' is not a joint");
      s.weights.emplace_back(joint, weight);
    }
    for (const IkAvoidDef& avoid : def.avoid) {
      IkAvoidSpec a = avoid.spec;
      for (const PathDef& link : avoid.links) a.links.push_back(resolve(link));
      s.avoid.push_back(std::move(a));
    }
    try {
      module->AddGroup(scene, std::move(s));
    } catch (const Error& e) {
      fail(def.where, e.what());
    }
  }
}

}  // namespace

std::shared_ptr<const ModelSectionDescriptor> IkGroupsSection() {
  auto section = std::make_shared<ModelSectionDescriptor>();
  section->key = "ik_groups";
  section->doc = "IK groups of each copy: tips and targets, joints' weights, obstacles to avoid";
  section->read = Read;
  section->apply = Apply;
  return section;
}

}  // namespace swarmsim::kinematics
