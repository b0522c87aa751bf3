#include "swarm/loader/ik.h"

#include <set>

#include "framework/error.h"
#include "framework/world.h"

namespace swarmsim::loader {
namespace {

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
uint8_t ReadConstraints(const ValueReader& values, const Field& field) {
  if (!field.node.IsSequence()) return ConstraintBit(values.Choice(field, kConstraintNames));
  uint8_t bits = 0;
  for (const Field& e : ListElements(values.file(), field, "constraints"))
    bits |= ConstraintBit(values.Choice(e, kConstraintNames));
  if (bits == 0)
    values.Fail(field, "'constraints' needs at least one of x, y, z, alpha, beta, gamma");
  return bits;
}

void CollectPaths(const ObjectSpec& spec, const std::string& prefix,
                  std::vector<std::string>* out) {
  for (const ObjectSpec& child : spec.children) {
    const std::string path = prefix.empty() ? child.name : prefix + "/" + child.name;
    out->push_back(path);
    CollectPaths(child, path, out);
  }
}

}  // namespace

std::vector<IkGroupDef> ReadIkGroups(const ModelFile& model, const ValueReader& values) {
  std::vector<IkGroupDef> out;
  std::set<std::string> names;
  for (const Field& element : ListElements(model.file, model.ik_groups, "IK groups")) {
    Fields f(model.file, element, "an IK group of model '" + model.name + "'");
    f.Expect({"name", "tips", "mode", "damping", "iterations", "tolerance", "orientation_tolerance",
              "max_step", "conditional", "automatic", "weights", "avoid"});
    IkGroupDef def;
    def.field = element;
    IkGroupSpec& s = def.spec;
    const Field name = f.Require("name");
    s.name = values.String(name);
    if (!names.insert(s.name).second)
      values.Fail(name, "model '" + model.name + "' already has an IK group '" + s.name + "'");
    if (f.Has("mode"))
      s.mode = values.Choice(f.Get("mode"), {"direct", "targets"}) == "direct"
                   ? IkMode::kDirect
                   : IkMode::kJointTargets;
    if (f.Has("damping")) s.damping = values.Number(f.Get("damping"), kNonNegative);
    if (f.Has("iterations"))
      s.max_iterations = static_cast<int>(values.Integer(f.Get("iterations"), 1, 10000));
    if (f.Has("tolerance")) s.position_tolerance = values.Number(f.Get("tolerance"), kPositive);
    if (f.Has("orientation_tolerance"))
      s.orientation_tolerance = values.Number(f.Get("orientation_tolerance"), kPositive);
    if (f.Has("max_step")) s.max_step = values.Number(f.Get("max_step"), kPositive);
    if (f.Has("conditional")) s.conditional = values.Bool(f.Get("conditional"));
    if (f.Has("automatic")) s.automatic = values.Bool(f.Get("automatic"));
    const Field tips = f.Require("tips");
    for (const Field& t : ListElements(model.file, tips, "tips")) {
      Fields tf(model.file, t, "a tip of IK group '" + s.name + "'");
      tf.Expect({"tip", "target", "base", "constraints"});
      IkTipDef tip;
      tip.tip = tf.Require("tip");
      tip.target = tf.Require("target");
      tip.base = tf.Get("base");
      if (tf.Has("constraints")) tip.constraints = ReadConstraints(values, tf.Get("constraints"));
      def.tips.push_back(std::move(tip));
    }
    if (def.tips.empty()) values.Fail(tips, "an IK group needs at least one {tip, target} pair");
    if (def.tips.size() > 4) values.Fail(tips, "an IK group has at most 4 tips");
    if (f.Has("weights")) {
      Fields w(model.file, f.Get("weights"), "the weights of IK group '" + s.name + "'");
      for (const Field& joint : w.fields()) {
        // A new Field for the key: assigning to a copy's node would write
        // the path over the weight in the parsed file (yaml.h).
        const Field path(joint.name, YAML::Node(joint.name), joint.key_mark, joint.key_mark);
        def.weights.emplace_back(path, values.Number(joint, kNonNegative));
      }
    }
    if (f.Has("avoid")) {
      // avoid: [{links: [paths], collection: PATH | environment, distance: m}]
      for (const Field& e : ListElements(model.file, f.Get("avoid"), "avoid")) {
        Fields af(model.file, e, "an avoid entry of IK group '" + s.name + "'");
        af.Expect({"links", "collection", "distance"});
        IkAvoidDef avoid;
        const Field links = af.Require("links");
        avoid.links = ListElements(model.file, links, "links");
        if (avoid.links.empty()) values.Fail(links, "'links' needs at least one link path");
        const Field obstacle = af.Require("collection");
        avoid.spec.obstacle = values.String(obstacle);
        avoid.spec.where = model.file.Where(obstacle.mark);
        if (af.Has("distance")) avoid.spec.distance = values.Number(af.Get("distance"), kPositive);
        def.avoid.push_back(std::move(avoid));
      }
    }
    out.push_back(std::move(def));
  }
  return out;
}

void AddIkGroups(const ModelFile& model, const std::vector<IkGroupDef>& groups,
                 const ObjectSpec& spec, ObjectId root, World* world) {
  if (groups.empty()) return;
  Scene& scene = world->scene();
  IkGroups* module = &kinematics::IkGroupsOf(world);
  std::vector<std::string> known;
  CollectPaths(spec, "", &known);
  // A path in the model, from its root: "leg1/footTip" (or "." for the root).
  auto resolve = [&](const Field& field, const char* what) {
    if (!field.node.IsScalar())
      model.file.Fail(field.mark, std::string("'") + what +
                                      "' must be an object path in the model, e.g. leg1/footTip");
    const std::string path = field.node.Scalar();
    ObjectId id;
    try {
      id = scene.FindObject(path == "." ? "." : "./" + path, root);
    } catch (const Error& e) {
      model.file.Fail(field.mark, e.what());
    }
    // The root is named after the copy; its name in the file (a URDF's root link) names it too.
    if (id.IsNull() && path == spec.name) id = root;
    if (id.IsNull())
      model.file.Fail(field.mark, "no object '" + path + "' in model '" + model.name + "'" +
                                      Suggest(path, known));
    return id;
  };
  for (const IkGroupDef& def : groups) {
    IkGroupSpec s = def.spec;
    for (const IkTipDef& t : def.tips) {
      IkTipSpec tip;
      tip.tip = resolve(t.tip, "tip");
      tip.target = resolve(t.target, "target");
      if (t.base.present()) tip.base = resolve(t.base, "base");
      tip.constraints = t.constraints;
      if (scene.type(tip.tip) == ObjectType::kDummy && scene.type(tip.target) == ObjectType::kDummy)
        scene.LinkDummies(tip.tip, tip.target);
      s.tips.push_back(tip);
    }
    for (const auto& [field, weight] : def.weights) {
      const ObjectId joint = resolve(field, "weights");
      if (scene.type(joint) != ObjectType::kJoint)
        model.file.Fail(field.mark, "'" + field.node.Scalar() + "' is not a joint");
      s.weights.emplace_back(joint, weight);
    }
    for (const IkAvoidDef& avoid : def.avoid) {
      IkAvoidSpec a = avoid.spec;
      for (const Field& link : avoid.links) a.links.push_back(resolve(link, "links"));
      s.avoid.push_back(std::move(a));
    }
    try {
      module->AddGroup(scene, std::move(s));
    } catch (const Error& e) {
      model.file.Fail(def.field.mark, e.what());
    }
  }
}

}  // namespace swarmsim::loader
