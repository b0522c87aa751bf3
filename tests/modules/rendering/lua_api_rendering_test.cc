// The scripts' side of modules/rendering (lua_api_rendering.cc): a vision
// sensor's resolution, image, depths and statistics packet; shape colours
// and lights; who may change what; and the errors.
#include <gtest/gtest.h>

#include <string>

#include "modules/rendering/objects.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::ModuleWorld;

// A robot "bot" carrying a vision sensor "eye" (16x12, looking along +x)
// at 0.25 m, a body "body", and a light "lamp"; a red cube "cube" 1 m ahead
// of it and a scene light "sun"; `code` runs on the robot.
struct RenderScripts {
  ModuleWorld w;
  ObjectId cube;
  explicit RenderScripts(const std::string& code) {
    const ObjectId bot = w.Robot("bot", {});
    w.Box("body", bot, {{0, 0, 0.05}, {}}, {0.1, 0.1, 0.1});
    VisionSensorRow eye;
    eye.lens.width = 16;
    eye.lens.height = 12;
    eye.floor = false;
    w.Add("vision_sensor", "eye", bot, {{0, 0, 0.25}, {}}, &eye);
    LightRow lamp;
    w.Add("light", "lamp", bot, {}, &lamp);
    w.Add("light", "sun", {}, {{0, 0, 5}, {}}, &lamp);
    ShapeData s;
    s.kind = ShapeKind::kBox;
    s.size = {0.5, 0.5, 0.5};
    s.color = {1, 0, 0};
    cube = w.scene().AddShape("cube", {}, {{1, 0, 0.25}, {}}, s);
    w.Script(bot, code);
  }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
};

TEST(LuaApiRenderingTest, ScriptsReadTheirSensorsImageDepthsAndPacket) {
  RenderScripts s(R"(
    function sysCall_sensing()
      local eye = sim.getObject('./eye')
      local res = sim.getVisionSensorRes(eye)
      local img, size = sim.getVisionSensorImg(eye)
      local depth = sim.getVisionSensorDepth(eye)
      local centre = (6 * 16 + 8) * 3
      print(string.format('res %dx%d bytes %d size %dx%d depths %d centre %.2f red %s', res[1],
        res[2], #img, size[1], size[2], #depth, depth[6 * 16 + 9],
        tostring(img:byte(centre + 1) > 2 * img:byte(centre + 3))))
      local result, packet = sim.readVisionSensor(eye)
      print(string.format('result %d packet %d', result, #packet))
    end
  )");
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_CONTAINS(s.Log(), "res 16x12 bytes 576 size 16x12 depths 192 centre 0.75 red true");
  EXPECT_CONTAINS(s.Log(), "result 0 packet 15");
}

TEST(LuaApiRenderingTest, ScriptsColourTheirShapesAndSwitchTheirLights) {
  RenderScripts s(R"(
    function sysCall_init()
      local body = sim.getObject('./body')
      sim.setShapeColor(body, {0, 0.5, 1})
      local c = sim.getShapeColor(body)
      local lamp = sim.getObject('./lamp')
      sim.setLightOn(lamp, false)
      sim.setLightColor(lamp, {1, 0.5, 0})
      print(string.format('colour %g %g %g lamp %s', c[1], c[2], c[3], tostring(sim.getLightOn(lamp))))
    end
  )");
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_CONTAINS(s.Log(), "colour 0 0.5 1 lamp false");
  const ShapeData& body = s.w.scene().shape(s.w.scene().FindObject("/bot/body"));
  EXPECT_EQ(body.color, (Vec3{0, 0.5, 1}));
  const LightRow& lamp = s.w.RowOf<LightRow>("light", s.w.scene().FindObject("/bot/lamp"));
  EXPECT_FALSE(lamp.on);
  EXPECT_EQ(lamp.color, (Vec3{1, 0.5, 0}));
}

std::string ErrorOfLine(const std::string& line) {
  RenderScripts s("function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiRenderingTest, MistakesAreErrorsNamingWhatIsWrong) {
  EXPECT_CONTAINS(ErrorOfLine("sim.getVisionSensorRes(sim.getObject('./body'))"),
                  "'/bot/body' is a shape, not a vision sensor");
  EXPECT_CONTAINS(ErrorOfLine("sim.setShapeColor(sim.getObject('/cube'), {0, 1, 0})"),
                  "a robot's script may change only its own robot's shapes ('/cube' belongs to "
                  "another robot or to the scene)");
  EXPECT_CONTAINS(ErrorOfLine("sim.setShapeColor(sim.getObject('./eye'), {0, 1, 0})"),
                  "'/bot/eye' is a vision_sensor, not a shape");
  EXPECT_CONTAINS(ErrorOfLine("sim.setLightOn(sim.getObject('/sun'), false)"),
                  "belongs to another robot or to the scene");
}

}  // namespace
}  // namespace swarmsim::rendering
