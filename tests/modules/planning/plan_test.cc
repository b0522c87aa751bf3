// The planner's front (modules/planning/plan.cc): space names, and a missing
// OMPL module, which is an error naming where it was looked for, from Plan
// and from LoadPlanner alike, never a crash. (planner_test.cc plans.)
#include <gtest/gtest.h>
#include <stdlib.h>

#include <string>

#include "modules/planning/ompl_module.h"
#include "modules/planning/planner.h"
#include "tests/framework/error_of.h"

namespace swarmsim::planning {
namespace {

using testing::ErrorOf;

TEST(PlanTest, SpacesByName) {
  for (const Space space : {Space::kSe2, Space::kSe3, Space::kDubins, Space::kReedsShepp}) {
    Space parsed = Space::kSe2;
    EXPECT_TRUE(ParseSpace(SpaceName(space), &parsed));
    EXPECT_EQ(parsed, space);
  }
  Space parsed = Space::kSe2;
  EXPECT_FALSE(ParseSpace("se4", &parsed));
}

TEST(PlanTest, AMissingOmplModuleIsAnErrorNamingWhereItWasLookedFor) {
  // This process has not planned yet: the module is looked for now.
  ASSERT_EQ(setenv(kOmplModuleVariable, "/nonexistent/libswarmsim_ompl.so", 1), 0);
  PlanRequest request;
  const std::string error = ErrorOf([&] { Plan(request, [](const Pose&) { return true; }); });
  EXPECT_CONTAINS(error, "path planning needs swarmsim's OMPL module");
  EXPECT_CONTAINS(error, "/nonexistent/libswarmsim_ompl.so: cannot open shared object file");
  EXPECT_EQ(ErrorOf([] { LoadPlanner(); }), error) << "the failure is kept";
}

}  // namespace
}  // namespace swarmsim::planning
