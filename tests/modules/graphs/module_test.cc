// The graphs module (modules/graphs/module.cc) through a World: a graph's
// streams sampled at the start and after every `every` steps, what each
// stream kind reads, full buffers (first or last samples kept), objects
// that go away, and the problems ResolveStream names.
#include "modules/graphs/module.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/graphs/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::graphs {
namespace {

using testing::ModuleWorld;

// Steps of 1/8 s, so that sample times add up exactly.
constexpr double kStep = 0.125;

GraphRow Graph(const std::vector<std::string>& streams) {
  GraphRow row;
  for (const std::string& s : streams) ParseStream(s, &row.streams);
  return row;
}

const Series& SeriesOf(ModuleWorld& w, ObjectId graph) {
  const auto* module = dynamic_cast<const GraphModule*>(w.world().find_module(kModuleName));
  EXPECT_NE(module, nullptr);
  const Series* series = module->Find(graph);
  EXPECT_NE(series, nullptr);
  return *series;
}

// A box at x = 0 moved 0.5 m along +x after every step.
struct Moving {
  ModuleWorld w{"kinematic", 1, kStep};
  ObjectId box = w.Box("box", {}, {}, {0.1, 0.1, 0.1});
  std::string Run(int steps) {
    std::string error = w.Run(0);
    for (int i = 0; i < steps && error.empty(); ++i) {
      const Pose X = w.scene().local_pose(box);
      w.scene().SetLocalPose(box, {X.p + Vec3{0.5, 0, 0}, X.q});
      error = w.Run(1);
    }
    return error;
  }
};

TEST(GraphModuleTest, SamplesAtTheStartAndAfterEveryStep) {
  Moving m;
  const GraphRow row = Graph({"position /box x", "height = position /box z"});
  const ObjectId graph = m.w.Add("graph", "trace", {}, {}, &row);
  ASSERT_EQ(m.Run(3), "");
  const Series& s = SeriesOf(m.w, graph);
  EXPECT_EQ(s.path, "/trace");
  EXPECT_EQ(s.file, "trace");
  ASSERT_EQ(s.count, 4u);
  ASSERT_EQ(s.width(), 3u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(s.sample(i)[0], kStep * i);
    EXPECT_DOUBLE_EQ(s.sample(i)[1], 0.5 * i);
    EXPECT_DOUBLE_EQ(s.sample(i)[2], 0);
  }
}

TEST(GraphModuleTest, EveryNStepsSamplesEveryNthStep) {
  Moving m;
  GraphRow row = Graph({"position /box x"});
  row.every = 3;
  const ObjectId graph = m.w.Add("graph", "trace", {}, {}, &row);
  ASSERT_EQ(m.Run(7), "");
  const Series& s = SeriesOf(m.w, graph);
  ASSERT_EQ(s.count, 3u);  // steps 0, 3 and 6
  EXPECT_DOUBLE_EQ(s.sample(1)[0], 3 * kStep);
  EXPECT_DOUBLE_EQ(s.sample(2)[1], 3.0);
}

TEST(GraphModuleTest, AFullBufferKeepsTheFirstSamplesOrCyclicTheLast) {
  for (const bool cyclic : {false, true}) {
    Moving m;
    GraphRow row = Graph({"position /box x"});
    row.buffer = 3;
    row.cyclic = cyclic;
    const ObjectId graph = m.w.Add("graph", "trace", {}, {}, &row);
    ASSERT_EQ(m.Run(5), "");  // 6 samples
    const Series& s = SeriesOf(m.w, graph);
    ASSERT_EQ(s.count, 3u);
    EXPECT_EQ(s.dropped, 3);
    const double first = cyclic ? 1.5 : 0;  // x of the oldest kept sample
    for (size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(s.sample(i)[1], first + 0.5 * i) << cyclic;
  }
}

TEST(GraphModuleTest, JointsOrientationsAndScriptStreamsRead) {
  ModuleWorld w("kinematic", 1, kStep);
  JointData slider;
  slider.settings.Edit().type = JointType::kPrismatic;
  slider.settings.Edit().mode = JointMode::kVelocity;
  slider.target_velocity = 0.4;
  w.scene().AddJoint("slider", {}, {}, slider);
  JointData hinge;
  hinge.settings.Edit().type = JointType::kRevolute;
  w.scene().AddJoint("hinge", {}, {}, hinge);
  w.Box("turned", {}, {{0, 0, 0}, Quat::FromYaw(0.75)}, {0.1, 0.1, 0.1});
  const GraphRow row =
      Graph({"joint /slider", "joint /hinge", "orientation /turned yaw", "script speed"});
  const ObjectId graph = w.Add("graph", "g", {}, {}, &row);
  ASSERT_EQ(w.Run(2), "");
  const Series& s = SeriesOf(w, graph);
  // The units of the joints' streams, now their types are known.
  EXPECT_EQ(s.settings.streams[0].unit, "m");
  EXPECT_EQ(s.settings.streams[1].unit, "rad");
  ASSERT_EQ(s.count, 3u);
  EXPECT_NEAR(s.sample(2)[1], 0.4 * 2 * kStep, 1e-12);
  EXPECT_DOUBLE_EQ(s.sample(2)[2], 0);
  EXPECT_NEAR(s.sample(2)[3], 0.75, 1e-12);
  EXPECT_TRUE(std::isnan(s.sample(2)[4]));  // no script set it
}

// A stream whose object is removed reads nan; a removed graph keeps its
// series (a run's outputs hold every graph that existed).
TEST(GraphModuleTest, RemovedObjectsReadNanAndRemovedGraphsKeepTheirSeries) {
  Moving m;
  const GraphRow row = Graph({"position /box x"});
  const ObjectId graph = m.w.Add("graph", "trace", {}, {}, &row);
  ASSERT_EQ(m.w.Run(1), "");
  m.w.scene().RemoveSubtree(m.box);
  ASSERT_EQ(m.w.Run(1), "");
  const Series& s = SeriesOf(m.w, graph);
  ASSERT_EQ(s.count, 3u);
  EXPECT_DOUBLE_EQ(s.sample(1)[1], 0);
  EXPECT_TRUE(std::isnan(s.sample(2)[1]));
  m.w.scene().RemoveSubtree(graph);
  ASSERT_EQ(m.w.Run(1), "");
  const Series& kept = SeriesOf(m.w, graph);
  EXPECT_FALSE(kept.alive);
  EXPECT_EQ(kept.count, 3u);
}

TEST(GraphModuleTest, TwoGraphsAtOnePathGetTwoFiles) {
  ModuleWorld w;
  const GraphRow row = Graph({"script a"});
  const ObjectId first = w.Add("graph", "g", {}, {}, &row);
  const ObjectId second = w.Add("graph", "g", {}, {}, &row);
  ASSERT_EQ(w.Run(0), "");
  EXPECT_EQ(SeriesOf(w, first).file, "g");
  EXPECT_EQ(SeriesOf(w, second).file, "g[1]");
}

TEST(GraphModuleTest, ResolveStreamNamesWhatIsWrong) {
  ModuleWorld w;
  const ObjectId bot = w.Robot("bot", {});
  w.Box("body", bot, {}, {0.1, 0.1, 0.1});
  const GraphRow row = Graph({"script a"});
  const ObjectId graph = w.Add("graph", "trace", bot, {}, &row);
  const auto problem = [&](const std::string& text) {
    std::vector<StreamSpec> specs;
    ParseStream(text, &specs);
    std::string why;
    const ObjectId id = ResolveStream(w.scene(), graph, specs[0], &why);
    return id.IsNull() ? why : "found " + w.scene().PathOf(id);
  };
  EXPECT_EQ(problem("position :/body x"), "found /bot/body");
  EXPECT_EQ(problem("joint :/body"), "':/body' is a shape, not a joint");
  EXPECT_EQ(problem("proximity :/body"), "':/body' is a shape, not a proximity_sensor");
  EXPECT_EQ(problem("distance :/body"), "':/body' is a shape, not a distance");
  EXPECT_CONTAINS(problem("position /nowhere x"), "'/nowhere' matches no object");
  EXPECT_CONTAINS(problem("position ./body x"),
                  "('./' looks below the graph: did you mean ':/body', in the graph's model?)");
}

}  // namespace
}  // namespace swarmsim::graphs
