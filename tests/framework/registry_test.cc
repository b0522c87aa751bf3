// The module registry (framework/registry.cc): what `swarmsim modules` lists,
// and the names it refuses so that a world file or a script never reaches
// the wrong thing (a command that Lua cannot call, a type that shadows
// another, a module or filter registered twice).
#include "framework/registry.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/phase.h"
#include "framework/vision_filter.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

int NoCommand(const SwarmsimCallContext*, const SwarmsimValue*, int, SwarmsimValue*, int, char*,
              size_t, void*) {
  return 0;
}
int NoCallback(const SwarmsimCallContext*, char*, size_t, void*) { return 0; }

ModuleDescriptor Descriptor(const std::string& name, const std::string& kind) {
  ModuleDescriptor d;
  d.info = {kind, name, "1.0", "a test module"};
  d.make = [](World*, const void*) -> std::unique_ptr<Module> { return nullptr; };
  return d;
}

// A module's or plugin's type cannot take a name that is already a type:
// the model files would silently build the other one.
TEST(ObjectTypesTest, ARegisteredTypeCannotShadowABuiltInOrLoaderType) {
  ModuleRegistry registry;
  const auto type = [](const char* name) {
    auto d = std::make_shared<ObjectTypeDescriptor>();
    d->name = name;
    d->description = "test";
    return std::shared_ptr<const ObjectTypeDescriptor>(d);
  };
  for (const char* taken : {"shape", "proximity_ring", "plugin_sensor"})
    EXPECT_THROW(registry.RegisterObjectType(type(taken)), Error) << taken;
  registry.RegisterObjectType(type("beacon"));
  EXPECT_THROW(registry.RegisterObjectType(type("beacon")), Error);
  ASSERT_EQ(registry.object_types().size(), 1u);
  EXPECT_STREQ(registry.object_types()[0]->name, "beacon");
}

// A command becomes sim.<name>: a name Lua cannot write after `sim.` would
// be unreachable, and a second one of a name would hide the first.
TEST(RegistryTest, ScriptCommandNamesAreLuaIdentifiersRegisteredOnce) {
  ModuleRegistry registry;
  for (const char* bad : {"", "2fast", "my-command", "a.b", "with space"})
    EXPECT_CONTAINS(ErrorOf([&] {
                      registry.RegisterScriptCommand({"", "p", "1", ""}, {bad, "", NoCommand});
                    }),
                    std::string("script command name '") + bad + "' is not a Lua identifier");
  registry.RegisterScriptCommand({"", "p", "1", "counts"}, {"count_2", "counts", NoCommand});
  ASSERT_NE(registry.FindScriptCommand("count_2"), nullptr);
  EXPECT_EQ(registry.FindScriptCommand("count_2")->description, "counts");
  EXPECT_EQ(registry.FindScriptCommand("count"), nullptr);
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterScriptCommand({"", "q", "1", ""}, {"count_2", "", NoCommand});
            }),
            "script command 'count_2' is registered twice");
  // Only the accepted command is listed.
  ASSERT_EQ(registry.modules().size(), 1u);
  EXPECT_EQ(registry.modules()[0].kind, "command");
  EXPECT_EQ(registry.modules()[0].name, "p");
}

// `swarmsim modules` lists every registration in order, each with the kind
// the registry gives it whatever the caller wrote.
TEST(RegistryTest, ModulesAreListedInRegistrationOrderWithTheirKind) {
  ModuleRegistry registry;
  registry.RegisterDynamics({"ignored", "null", "1", "moves nothing"}, {.substeps = false},
                            [] { return std::make_unique<testing::NullDynamics>(); });
  registry.RegisterCalculation({"ignored", "solver", "2.1", "solves"}, [] { return nullptr; });
  registry.RegisterModule(Descriptor("metrics", "metric"));
  std::vector<std::string> listed;
  for (const ModuleInfo& m : registry.modules()) listed.push_back(m.kind + " " + m.name);
  const std::vector<std::string> expected = {"dynamics null", "calculation solver",
                                             "metric metrics"};
  EXPECT_EQ(listed, expected);
  EXPECT_EQ(registry.modules()[1].version, "2.1");
  // A calculation module runs in the actuate phase at order 100.
  const ModuleDescriptor* solver = registry.FindModule("solver");
  ASSERT_NE(solver, nullptr);
  EXPECT_EQ(solver->phases, PhaseBit(Phase::kActuate));
  EXPECT_EQ(solver->order, 100);
  EXPECT_FALSE(solver->every_world);
  ASSERT_EQ(registry.ModulesOfKind("metric").size(), 1u);
  EXPECT_EQ(registry.ModulesOfKind("metric")[0]->info.name, "metrics");
  EXPECT_TRUE(registry.ModulesOfKind("camera").empty());
  EXPECT_EQ(registry.FindModule("nothing"), nullptr);
}

TEST(RegistryTest, AModuleNeedsANameAndAFactoryAndComesOnce) {
  ModuleRegistry registry;
  ModuleDescriptor nameless = Descriptor("", "metric");
  EXPECT_EQ(ErrorOf([&] { registry.RegisterModule(nameless); }),
            "a module needs a name and a way to make it");
  ModuleDescriptor no_factory = Descriptor("m", "metric");
  no_factory.make = nullptr;
  EXPECT_EQ(ErrorOf([&] { registry.RegisterModule(no_factory); }),
            "a module needs a name and a way to make it");
  registry.RegisterModule(Descriptor("m", "metric"));
  EXPECT_EQ(ErrorOf([&] { registry.RegisterModule(Descriptor("m", "other")); }),
            "module 'm' is registered twice");
  EXPECT_EQ(registry.modules().size(), 1u);
}

// A world's `physics:` names a backend: a wrong one lists those there are.
TEST(RegistryTest, UnknownPhysicsNamesTheAvailableBackends) {
  ModuleRegistry registry = testing::NullRegistry();
  registry.RegisterDynamics({"", "other", "1", ""}, {},
                            [] { return std::make_unique<testing::NullDynamics>(); });
  EXPECT_NE(registry.MakeDynamics("other"), nullptr);
  EXPECT_TRUE(registry.HasDynamics("null"));
  EXPECT_FALSE(registry.HasDynamics("box2d"));
  EXPECT_EQ(registry.DynamicsNames(), (std::vector<std::string>{"null", "other"}));
  EXPECT_EQ(ErrorOf([&] { registry.MakeDynamics("box2d"); }),
            "unknown physics backend 'box2d' (available: null, other)");
  EXPECT_EQ(ErrorOf([&] { ModuleRegistry().MakeDynamics("null"); }),
            "unknown physics backend 'null' (available: (none))");
  // A backend registered without a bare loop has no "<physics>-only" row.
  EXPECT_EQ(registry.FindBareLoop("null"), nullptr);
  registry.RegisterDynamics(
      {"", "timed", "1", ""}, {}, [] { return std::make_unique<testing::NullDynamics>(); },
      [](const Scene&, double, int, int steps, double) { return 0.5 * steps; });
  ASSERT_NE(registry.FindBareLoop("timed"), nullptr);
  EXPECT_EQ((*registry.FindBareLoop("timed"))(Scene(), 0.01, 1, 4, -9.81), 2.0);
}

// What a backend declares is what callers get (Python's World.planar, the
// summary's physics line), never a guess from its name.
TEST(RegistryTest, DynamicsCapabilitiesAreWhatTheBackendDeclared) {
  ModuleRegistry registry;
  registry.RegisterDynamics({"", "flat", "1", ""}, {.planar = true},
                            [] { return std::make_unique<testing::NullDynamics>(); });
  registry.RegisterDynamics({"", "box2d", "1", ""}, {.planar = false, .substeps = false},
                            [] { return std::make_unique<testing::NullDynamics>(); });
  EXPECT_TRUE(registry.dynamics_capabilities("flat").planar);
  EXPECT_TRUE(registry.dynamics_capabilities("flat").substeps);
  EXPECT_FALSE(registry.dynamics_capabilities("box2d").planar);  // the name says nothing
  EXPECT_FALSE(registry.dynamics_capabilities("box2d").substeps);
  EXPECT_EQ(ErrorOf([&] { registry.dynamics_capabilities("ode"); }),
            "unknown physics backend 'ode' (available: flat, box2d)");
}

TEST(RegistryTest, PhaseCallbacksNeedAKnownPhaseAndAFunction) {
  ModuleRegistry registry;
  const SwarmsimPhaseCallback fn = NoCallback;
  for (Phase phase : {Phase::kCount, static_cast<Phase>(200)})
    EXPECT_EQ(ErrorOf([&] {
                registry.RegisterPhaseCallback({"", "p", "1", ""},
                                               {"p:bad", phase, PhaseEdge::kEnd, false, fn});
              }),
              "phase callback 'p:bad' has an unknown phase or no function");
  EXPECT_THROW(registry.RegisterPhaseCallback(
                   {"", "p", "1", ""}, {"p:none", Phase::kRecord, PhaseEdge::kEnd, false, nullptr}),
               Error);
  registry.RegisterPhaseCallback({"", "p", "1", ""},
                                 {"p:record", Phase::kRecord, PhaseEdge::kEnd, true, fn});
  ASSERT_EQ(registry.phase_callbacks().size(), 1u);
  EXPECT_TRUE(registry.phase_callbacks()[0].per_robot);
  EXPECT_EQ(registry.modules().at(0).kind, "callback");
}

TEST(RegistryTest, VisionFiltersNeedANameAWayToMakeThemAndComeOnce) {
  ModuleRegistry registry;
  const auto filter = [](const char* name, bool makeable) {
    auto d = std::make_shared<VisionFilterDescriptor>();
    d->name = name;
    d->description = "test";
    if (makeable) d->make = [](const ObjectReader&) { return nullptr; };
    return std::shared_ptr<const VisionFilterDescriptor>(d);
  };
  EXPECT_EQ(ErrorOf([&] { registry.RegisterVisionFilter(filter("", true)); }),
            "a vision filter element needs a name");
  EXPECT_EQ(ErrorOf([&] { registry.RegisterVisionFilter(filter("blur", false)); }),
            "vision filter element 'blur' has no way to make it");
  registry.RegisterVisionFilter(filter("blur", true));
  EXPECT_EQ(ErrorOf([&] { registry.RegisterVisionFilter(filter("blur", true)); }),
            "vision filter element 'blur' is registered twice");
  ASSERT_NE(registry.FindVisionFilter("blur"), nullptr);
  EXPECT_EQ(registry.FindVisionFilter("sharpen"), nullptr);
  EXPECT_EQ(registry.modules().size(), 1u);
  EXPECT_EQ(registry.modules()[0].kind, "vision filter");
}

}  // namespace
}  // namespace swarmsim
