// Model-file sections that modules own (framework/model_section.h): the
// loader hands a model file's keys it does not know itself (and a models
// entry's keys of the same name) to the registered sections, with the
// model's parameter values, applies what they read to every copy built
// from the model's description, and lists their keys when a key is
// unknown. A section a test registers goes through with no loader change;
// the IK groups' own: tests/modules/kinematics/ik_model_section_test.cc.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/model_section.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

// `marks: [{path: P, size: S}]`: each copy built from the model's
// description notes its marks (the path resolved in the copy).
struct Marks final : ModelSectionData {
  struct Mark {
    std::string path, where;
    double size = 0;
  };
  std::vector<Mark> marks;
  std::string Describe() const override {
    return "marks (" + std::to_string(marks.size()) + " marks)";
  }
};

struct Applied {
  std::string copy, object, where, root_name;
  double size = 0;
  std::vector<std::string> paths;
};
std::vector<Applied>* applied = nullptr;  // the test's log

std::shared_ptr<const ModelSectionData> ReadMarks(const ObjectReader& top,
                                                  const std::string& model) {
  if (!top.Has("marks")) return nullptr;
  auto data = std::make_shared<Marks>();
  for (const auto& m : top.Maps("marks", "marks", "a mark of model '" + model + "'")) {
    m->Expect(std::vector<std::string>{"path", "size"});
    data->marks.push_back(
        {m->String("path", true), m->Where("path"), m->Number("size", kPositive)});
  }
  return data;
}

void ApplyMarks(const ModelSectionData& data, const ModelCopy& copy, World* world) {
  for (const Marks::Mark& mark : static_cast<const Marks&>(data).marks) {
    const ObjectId id =
        world->scene().FindObject(mark.path == "." ? "." : "./" + mark.path, copy.root);
    if (id.IsNull()) throw Error(mark.where + ": no object '" + mark.path + "'");
    const Scene& scene = world->scene();
    applied->push_back({scene.instance(scene.instance_of(copy.root)).name, scene.name(id),
                        mark.where, copy.root_name, mark.size,
                        std::vector<std::string>(copy.paths.begin(), copy.paths.end())});
  }
}

class ModelSectionsTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    auto section = std::make_shared<ModelSectionDescriptor>();
    section->key = "marks";
    section->doc = "a test section: marks on the model's objects";
    section->read = ReadMarks;
    section->apply = ApplyMarks;
    registry_.RegisterModelSection(section);
    EXPECT_CONTAINS(testing::ErrorOf([&] { registry_.RegisterModelSection(section); }),
                    "model-file section 'marks' is registered twice");
    applied = &log_;
    Write("bot.yaml",
          "model: bot\n"
          "parameters: {size: 0.5}\n"
          "objects:\n"
          "  name: body\n"
          "  type: dummy\n"
          "  children: [{name: eye, type: dummy}]\n"
          "marks: [{path: eye, size: $size}]\n");
  }
  void TearDown() override {
    applied = nullptr;
    WorldDirTest::TearDown();
  }
  std::vector<Applied> log_;
};

TEST_F(ModelSectionsTest, EachCopyBuiltFromTheModelGetsWhatTheSectionRead) {
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "arena: {size: 10}\n"
      "models:\n"
      "  - model: bot.yaml\n"
      "    count: 3\n"
      "    distribute: {region: arena}\n"
      "    instances: [{index: 2, parameters: {size: 0.25}}]\n"
      "    marks: [{path: ., size: 1}]\n");
  // Copy 0 (the entry's first) and copy 2 (values of its own) are built
  // from the description, each with the model's marks and the entry's;
  // copy 1 is duplicated from copy 0 (a module follows duplicates itself).
  ASSERT_EQ(log_.size(), 4u);
  EXPECT_EQ(log_[0].copy, "bot#0");
  EXPECT_EQ(log_[0].object, "eye");
  EXPECT_EQ(log_[0].size, 0.5);
  EXPECT_EQ(log_[0].root_name, "body");
  EXPECT_EQ(log_[0].paths, std::vector<std::string>{"eye"});
  EXPECT_CONTAINS(log_[0].where, "bot.yaml:7:");
  EXPECT_EQ(log_[1].copy, "bot#0");
  EXPECT_EQ(log_[1].object, "body");  // the entry's own, from the world file: the root
  EXPECT_CONTAINS(log_[1].where, "world.yaml:8:");
  EXPECT_EQ(log_[2].copy, "bot#2");
  EXPECT_EQ(log_[2].size, 0.25);  // its own value
  EXPECT_EQ(log_[3].copy, "bot#2");
  ASSERT_EQ(w.models.size(), 1u);
  EXPECT_EQ(w.models[0].modules, (std::vector<std::string>{"marks (1 marks)", "marks (1 marks)"}));
}

TEST_F(ModelSectionsTest, MistakesAndUnknownKeysNameTheirPlace) {
  const std::string world =
      "simulation: {physics: kinematic}\nmodels: [{model: bot.yaml, position: [0, 0]}]\n";
  Write("bot.yaml", "model: bot\nobjects: {name: body, type: dummy}\nmarks: [{path: nose}]\n");
  EXPECT_CONTAINS(testing::ErrorOf([&] { Load(world); }), "'size' must be a positive number");
  Write("bot.yaml",
        "model: bot\nobjects: {name: body, type: dummy}\nmarks: [{path: nose, size: 1}]\n");
  EXPECT_CONTAINS(testing::ErrorOf([&] { Load(world); }), "bot.yaml:3:16: no object 'nose'");
  // An unknown key of the model file lists the registered sections' keys
  // with the loader's own.
  Write("bot.yaml", "model: bot\nobjects: {name: body, type: dummy}\nmark: []\n");
  EXPECT_CONTAINS(testing::ErrorOf([&] { Load(world); }),
                  "bot.yaml:3:1: unknown key 'mark' in the model file; did you mean 'marks'?");
  Write("bot.yaml", "model: bot\nobjects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(testing::ErrorOf([&] {
                    Load(
                        "simulation: {physics: kinematic}\n"
                        "models: [{model: bot.yaml, position: [0, 0], mark: []}]\n");
                  }),
                  "did you mean 'marks'?");
}

}  // namespace
}  // namespace swarmsim
