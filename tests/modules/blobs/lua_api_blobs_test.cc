// The scripts' side of modules/blobs (lua_api_blobs.cc): sim.setLedColor,
// sim.setLedOn, sim.getLedColor, sim.readBlobCamera and their errors.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "tests/modules/blobs/blob_world.h"

namespace swarmsim {
namespace {

using namespace blobs_test;  // blob_world.h

// --- Scripts -----------------------------------------------------------------------------

// Two robots 0.5 m apart on x, each with an LED and a camera; `code` runs on
// robot 0's root. Returns what the scripts printed.
std::vector<std::string> RunScript(const std::string& code, std::string* error) {
  BlobWorld w;
  std::vector<std::string> log;
  w.world().set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  for (int i = 0; i < 2; ++i) {
    const ObjectId root = w.Robot(0.5 * i, 0);
    w.Led(root, {0, 0, 0.083}, kRed);
    w.Camera(root, {{0, 0, 0.127}, {}});
  }
  w.scene().AddShape("wall", {}, {{0, 1, 0.1}, {}}, Box({1, 0.1, 0.2}));
  w.scene().AttachScript(w.scene().instance(0).root,
                         std::make_shared<const ScriptSource>(ScriptSource{"bot.lua", code}));
  try {
    w.world().Start();
    for (int i = 0; i < 3; ++i) w.world().Step();
  } catch (const Error& e) {
    *error = e.what();
  }
  return log;
}

TEST(BlobCameraTest, ScriptsSetTheirLedAndReadTheirCamera) {
  std::string error;
  const auto log = RunScript(R"(
    function sysCall_init()
      led, camera = sim.getObject('./led'), sim.getObject('./camera')
      sim.setLedColor(led, {0, 0.5, 1})
      sim.setLedOn(led, false)
      local c, on = sim.getLedColor(led)
      print(string.format('led %g %g %g %s', c[1], c[2], c[3], tostring(on)))
      sim.setLedOn(led, true)
    end
    function sysCall_sensing()
      local blobs = sim.readBlobCamera(camera)
      local b = blobs[1]
      print(string.format('%d blob: %g %g %g d=%.3f b=%.3f e=%.3f other=%s', #blobs,
        b.color[1], b.color[2], b.color[3], b.distance, b.bearing, b.elevation,
        tostring(b.handle == sim.getObject('/bot#1/led'))))
    end
  )",
                             &error);
  EXPECT_EQ(error, "");
  ASSERT_GE(log.size(), 2u);
  EXPECT_NE(log[0].find("led 0 0.5 1 false"), std::string::npos) << log[0];
  EXPECT_NE(log[1].find("1 blob: 1 0 0 d=0.502 b=0.000 e=-0.088 other=true"), std::string::npos)
      << log[1];
}

TEST(BlobCameraTest, ScriptErrorsNameWhatIsWrong) {
  const auto error_of = [](const std::string& code) {
    std::string error;
    RunScript("function sysCall_init()\n" + code + "\nend\n", &error);
    return error;
  };
  EXPECT_NE(error_of("sim.readBlobCamera(sim.getObject('./led'))")
                .find("sim.readBlobCamera: object /bot#0/led is a led, not a blob_camera"),
            std::string::npos);
  EXPECT_NE(error_of("sim.setLedColor(sim.getObject('/bot#1/led'), {1, 0, 0})")
                .find("may set only its own LEDs ('/bot#1/led' belongs to another robot"),
            std::string::npos);
  EXPECT_NE(error_of("sim.getLedColor(sim.getObject('/bot#1/led'))").find("read only its own LEDs"),
            std::string::npos);
  EXPECT_NE(error_of("sim.setLedColor(sim.getObject('./led'), {1, 2, 0})")
                .find("the colour must be {r, g, b} with each component between 0 and 1"),
            std::string::npos);
  EXPECT_NE(error_of("sim.setLedOn(sim.getObject('./led'), 1)").find("bad argument #2"),
            std::string::npos);
}

}  // namespace
}  // namespace swarmsim
