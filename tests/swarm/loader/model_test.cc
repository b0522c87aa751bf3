// Model files (swarm/loader/model.cc): the file checked (name, declared
// parameters, one root object), its objects resolved with the entry's
// parameters, and the footprint a copy is placed by.
#include "swarm/loader/model.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "framework/scene.h"
#include "tests/swarm/loader/yaml_file.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::Yaml;
using testing::YamlDir;

// Reads `text` as a model file used by "w.yaml:3:5".
ModelFile Model(const std::string& text) {
  return ReadModelFile(Yaml(text, "m.yaml"), "w.yaml:3:5");
}

std::string ModelError(const std::string& text) {
  return ErrorOf([&] { Model(text); });
}

TEST(ModelTest, ParameterNamesAreLuaIdentifiers) {
  for (const char* name : {"speed", "_x", "a1", "max_speed", "End"})
    EXPECT_TRUE(IsParameterName(name)) << name;
  for (const char* name : {"", "1a", "a-b", "a b", "end", "local", "nil", "function", "x.y"})
    EXPECT_FALSE(IsParameterName(name)) << name;
}

TEST(ModelTest, AModelFileIsANameParametersAndOneRootObject) {
  const ModelFile m = Model(
      "model: disc-2\n"
      "description: a disc\n"
      "parameters:\n"
      "  r: {default: 0.2, unit: m, range: [0.1, 1], description: its radius}\n"
      "  label: plain\n"
      "objects: [{type: shape, shape: sphere, radius: $r}]\n");
  EXPECT_EQ(m.name, "disc-2");
  ASSERT_EQ(m.parameters.size(), 2u);
  EXPECT_EQ(m.parameters[0].name, "r");
  EXPECT_EQ(m.parameters[0].unit, "m");
  EXPECT_EQ(m.parameters[0].description, "its radius");
  EXPECT_TRUE(m.parameters[0].has_range);
  EXPECT_EQ(m.parameters[0].min, 0.1);
  EXPECT_EQ(m.parameters[0].max, 1);
  EXPECT_EQ(m.parameters[0].default_value.node.Scalar(), "0.2");
  EXPECT_EQ(m.parameters[1].name, "label");
  EXPECT_FALSE(m.parameters[1].has_range);
  EXPECT_EQ(m.parameters[1].default_value.node.Scalar(), "plain");
  EXPECT_TRUE(m.root.node.IsMap()) << "a list of one object is that object";
  EXPECT_TRUE(m.top.node.IsMap()) << "model-file sections read their keys from it";
  fs::remove_all(YamlDir());
}

TEST(ModelTest, AModelFilesMistakesAreNamedAtTheirPlace) {
  const std::string name = DisplayPath(YamlDir() / "m.yaml");
  EXPECT_EQ(ModelError("- a\n- b\n"),
            name +
                ":1:1: a model file must be a mapping with 'model', 'parameters' and 'objects' "
                "(got a list; used by w.yaml:3:5)");
  EXPECT_EQ(ModelError("model: bot\nobject: {type: dummy}\n"),
            name + ":2:1: unknown key 'object' in the model file; did you mean 'objects'?");
  EXPECT_EQ(ModelError("model: my bot\nobjects: {type: dummy}\n"),
            name +
                ":1:8: model name 'my bot' may use only letters, digits, '_' and '-' (it names "
                "the copies: name#0, name#1, ...)");
  EXPECT_EQ(ModelError("model: bot\nparameters: {end: 1}\nobjects: {type: dummy}\n"),
            name +
                ":2:14: parameter name 'end' must be a Lua identifier (letters, digits, '_'; "
                "not a keyword)");
  EXPECT_EQ(ModelError("model: bot\nparameters: {a: [1, 2]}\nobjects: {type: dummy}\n"),
            name +
                ":2:17: parameter 'a' must be a value or {default, unit, range, description} "
                "(got a list)");
  EXPECT_EQ(ModelError("model: bot\nparameters: {a: {default: 1, range: [0, 1, 2]}}\n"
                       "objects: {type: dummy}\n"),
            name + ":2:37: 'range' must be [min, max], two numbers (got a list of 3)");
  EXPECT_EQ(ModelError("model: bot\nparameters: {a: {default: 1, range: [0, x]}}\n"
                       "objects: {type: dummy}\n"),
            name +
                ":2:41: 'range' must be [min, max], two numbers: its max is not a number (got "
                "\"x\")");
  EXPECT_EQ(ModelError("model: bot\nparameters: {a: {default: 1, range: [2, 1]}}\n"
                       "objects: {type: dummy}\n"),
            name + ":2:37: 'range' must be [min, max] with min <= max (got min 2 > max 1)");
  EXPECT_EQ(ModelError("model: bot\nparameters: {a: {range: [0, 1]}}\nobjects: {type: dummy}\n"),
            name + ":2:17: 'default' is required in parameter 'a'");
  EXPECT_EQ(ModelError("model: bot\nobjects: [{type: dummy}, {type: dummy}]\n"),
            name +
                ":2:10: 'objects' is the model's root object (the body copies are placed by), "
                "with the others under its 'children' (got a list of 2)");
  EXPECT_EQ(ModelError("model: bot\n"), name + ":1:1: 'objects' is required in the model file");
  fs::remove_all(YamlDir());
}

// `model` resolved with parameters {r: 0.1} (shadowing none of the world's).
ObjectSpec Resolve(const ModelFile& model) {
  static const ParameterSet world;
  static const ParameterSet params{{"r", 0.1}};
  Expressions expressions;
  ScriptCache scripts;
  const ValueReader values(model.file, &expressions, Scope{&world, &params, nullptr});
  return ResolveModel(model, values, &scripts);
}

TEST(ModelTest, ObjectsAreResolvedWithTheEntrysParameters) {
  const ModelFile m = Model(
      "model: arm\n"
      "parameters: {r: 0.3}\n"
      "objects:\n"
      "  type: shape\n"
      "  shape: cylinder\n"
      "  radius: \"= 2 * r\"\n"
      "  height: 0.1\n"
      "  children:\n"
      "    - {name: ball, type: shape, shape: sphere, radius: $r, position: [1, 0, 0.5]}\n"
      "    - {name: tip, type: dummy, position: [0, 0, 2], heading_deg: 90}\n");
  const ObjectSpec root = Resolve(m);
  EXPECT_EQ(root.name, "arm") << "the root is named after the model";
  EXPECT_EQ(root.type, ObjectType::kShape);
  const ShapeData* body = root.AsShape();
  ASSERT_NE(body, nullptr);
  EXPECT_EQ(body->size.x, 0.2) << "the entry's r, not the default";
  ASSERT_EQ(root.children.size(), 2u);
  EXPECT_EQ(root.children[0].name, "ball");
  EXPECT_EQ(root.children[0].X_PO.p.x, 1);
  EXPECT_EQ(root.children[1].type, ObjectType::kDummy);
  EXPECT_NEAR(root.children[1].X_PO.q.Rotate({1, 0, 0}).y, 1, 1e-12);
  // The footprint: the ball reaches 1 + r from the axis, from the body's
  // bottom (-0.05) to the ball's top (0.5 + r).
  const Footprint fp = ComputeFootprint(root);
  EXPECT_DOUBLE_EQ(fp.radius, 1.1);
  EXPECT_DOUBLE_EQ(fp.bottom, -0.05);
  EXPECT_DOUBLE_EQ(fp.top, 0.6);
  fs::remove_all(YamlDir());
}

TEST(ModelTest, ObjectMistakesAreNamedAtTheirPlace) {
  const std::string name = DisplayPath(YamlDir() / "m.yaml");
  const auto error = [&](const std::string& text) {
    const ModelFile m = Model(text);
    return ErrorOf([&] { Resolve(m); });
  };
  EXPECT_EQ(error("model: bot\nobjects: {type: dummy, children: [{name: a/b, type: dummy}]}\n"),
            name +
                ":2:42: object name 'a/b' must be non-empty, without spaces, '/', '[' or ']' "
                "(it is used in paths such as ./leftMotor)");
  EXPECT_EQ(error("model: bot\nobjects: {type: dummy, children: [{type: dummy}]}\n"),
            name + ":2:35: 'name' is required in an object of model 'bot'");
  EXPECT_NE(
      error("model: bot\nobjects: {type: dumy}\n").find(name + ":2:17: 'type' must be one of "),
      std::string::npos);
  EXPECT_NE(error("model: bot\nobjects: {type: dumy}\n").find("did you mean 'dummy'?"),
            std::string::npos);
  EXPECT_EQ(
      error("model: bot\nobjects: {type: dummy, heading_deg: 90, orientation_deg: [0, 0, 1]}\n"),
      name +
          ":2:37: give either 'orientation_deg: [roll, pitch, yaw]' or 'heading_deg', "
          "not both");
  fs::remove_all(YamlDir());
}

}  // namespace
}  // namespace swarmsim::loader
