// Vision sensors, cameras and lights (modules/rendering) as a user writes
// them: a world file, a step, and what the sensor saw.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paint/png_io.h"
#include "modules/proximity/proximity_sensor.h"
#include "modules/rendering/objects.h"
#include "modules/rendering/render.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using rendering::VisionSensorRow;

class RenderingTest : public testing::WorldDirTest {
 protected:
  std::string ErrorOf(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  static VisionSensorRow& Sensor(World& world, const std::string& path) {
    const ObjectId id = world.scene().FindObject(path);
    EXPECT_FALSE(id.IsNull()) << path;
    return *static_cast<VisionSensorRow*>(world.scene().row_data(id));
  }
  // Saves an image for a person to look at when SWARMSIM_TEST_IMAGES names a folder.
  static void Keep(const Image& image, const std::string& name) {
    if (const char* dir = std::getenv("SWARMSIM_TEST_IMAGES"))
      paint::WritePng(std::filesystem::path(dir) / (name + ".png"), image.width, image.height,
                      image.rgb);
  }
};

// A red cube 2 m ahead of a sensor 0.25 m above the floor.
constexpr char kRedCube[] = R"(simulation: {physics: kinematic, time_step: 0.1}
objects:
  - {name: cube, type: shape, shape: box, size: [0.5, 0.5, 0.5], position: [2, 0, 0.25],
     color: [0.9, 0.1, 0.1]}
  - {name: eye, type: vision_sensor, position: [0, 0, 0.25], resolution: [64, 48], fov_deg: 60}
)";

TEST_F(RenderingTest, AVisionSensorSeesAColouredBoxAheadAtItsDistance) {
  LoadedWorld w = Load(kRedCube);
  w.world->Start();
  const VisionSensorRow& s = Sensor(*w.world, "/eye");
  ASSERT_EQ(s.image.width, 64);
  ASSERT_EQ(s.image.height, 48);
  Keep(s.image, "red_cube");
  const uint8_t* centre = s.image.Pixel(32, 24);
  EXPECT_GT(centre[0], 120) << "the cube's red";
  EXPECT_LT(centre[1], 60);
  EXPECT_LT(centre[2], 60);
  // The face toward the sensor is 1.75 m away along the view axis.
  EXPECT_NEAR(s.image.depth[24 * 64 + 32], 1.75, 0.01);
  // The cube's face spans 0.5 m at 1.75 m: 64 (0.25 / 1.75) / tan(30 deg), ~16 pixels.
  int red = 0;
  for (int x = 0; x < 64; ++x) red += s.image.Pixel(x, 24)[0] > 120 && s.image.Pixel(x, 24)[1] < 60;
  EXPECT_NEAR(red, 64 * (0.25 / 1.75) / std::tan(M_PI / 6), 1.5);
  // Above the horizon nothing: the background; below it, the floor (grey).
  const uint8_t* sky = s.image.Pixel(2, 2);
  EXPECT_EQ(sky[0] + sky[1] + sky[2], 0);
  const uint8_t* floor = s.image.Pixel(2, 45);
  EXPECT_GT(floor[0], 100);
  EXPECT_NEAR(floor[0], floor[2], 20) << "grey";
}

TEST_F(RenderingTest, ObjectsOutsideTheDetectableSetAreNotSeen) {
  std::string world = kRedCube;
  world.replace(world.find("fov_deg: 60}"), 12, "fov_deg: 60, detectable: /nothing}");
  world += "  - {name: nothing, type: dummy}\n";
  LoadedWorld w = Load(world);
  w.world->Start();
  const Image& image = Sensor(*w.world, "/eye").image;
  const uint8_t* centre = image.Pixel(32, 24);
  EXPECT_FALSE(centre[0] > 120 && centre[1] < 60) << "the cube is not detectable";
  EXPECT_GT(image.Pixel(2, 45)[0], 100) << "the sensor rendered: it sees the floor";
  EXPECT_NEAR(image.depth[24 * 64 + 32], 10.0, 1e-3) << "nothing at the cube's place: far";
}

// `visible: false` (an imported link's collision geometry): cameras do not
// see the cube, a proximity ray along the same axis still detects it.
TEST_F(RenderingTest, AnInvisibleShapeIsNotSeenButStillDetected) {
  std::string world = kRedCube;
  world.replace(world.find("color: [0.9, 0.1, 0.1]}"), 23,
                "color: [0.9, 0.1, 0.1], visible: false}");
  world +=
      "  - {name: ray, type: proximity_sensor, range: 5, position: [0, 0, 0.25], "
      "orientation_deg: [0, 90, 0]}\n";
  LoadedWorld w = Load(world);
  w.world->Start();
  w.world->Step();
  const Image& image = Sensor(*w.world, "/eye").image;
  const uint8_t* centre = image.Pixel(32, 24);
  EXPECT_FALSE(centre[0] > 120 && centre[1] < 60) << "the invisible cube is not drawn";
  EXPECT_NEAR(image.depth[24 * 64 + 32], 10.0, 1e-3) << "nothing at the cube's place: far";
  const ObjectId ray = w.world->scene().FindObject("/ray");
  ASSERT_FALSE(ray.IsNull());
  const auto& reading = *static_cast<const ProximitySensorData*>(w.world->scene().row_data(ray));
  EXPECT_TRUE(reading.detected) << "the ray still meets the cube";
  EXPECT_NEAR(reading.distance, 1.75, 1e-6);
}

TEST_F(RenderingTest, AnOrthographicSensorLookingDownSeesTheCubeFromAbove) {
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "objects:\n"
      "  - {name: cube, type: shape, shape: box, size: [0.5, 0.5, 0.5], position: [0, 0, 0.25],"
      " color: [0.1, 0.1, 0.9]}\n"
      "  - {name: top, type: vision_sensor, position: [0, 0, 3], orientation_deg: [0, 90, 0],"
      " projection: orthographic, ortho_width: 2, resolution: [40, 40], near: 0.1, far: 5}\n");
  w.world->Start();
  const VisionSensorRow& s = Sensor(*w.world, "/top");
  Keep(s.image, "ortho_top");
  // 0.5 m of 2 m: 10 pixels of 40, centred.
  int blue = 0;
  for (int x = 0; x < 40; ++x)
    blue += s.image.Pixel(x, 20)[2] > 120 && s.image.Pixel(x, 20)[0] < 60;
  EXPECT_NEAR(blue, 10, 1);
  EXPECT_NEAR(s.image.depth[20 * 40 + 20], 2.5, 0.01);
}

TEST_F(RenderingTest, ImagesAreTheSameWhateverTheThreadCount) {
  std::string world =
      "simulation: {physics: kinematic, seed: 3}\n"
      "objects:\n";
  for (int i = 0; i < 8; ++i) {
    const std::string n = std::to_string(i);
    world += "  - {name: s" + n + ", type: vision_sensor, position: [0, 0, 0.3], heading_deg: " +
             std::to_string(45 * i) + ", resolution: [32, 24]}\n";
    world += "  - {name: b" + n +
             ", type: shape, shape: cylinder, radius: 0.2, height: 0.6, "
             "position: [" +
             std::to_string(1.5 * std::cos(i * 0.8)) + ", " +
             std::to_string(1.5 * std::sin(i * 0.8)) + ", 0.3], color: [0.2, 0." + n + ", 0.7]}\n";
  }
  LoadedWorld one = Load(world, 1);
  LoadedWorld two = Load(world, 2);
  one.world->Start();
  two.world->Start();
  for (int i = 0; i < 8; ++i) {
    const std::string path = "/s" + std::to_string(i);
    EXPECT_EQ(Sensor(*one.world, path).image.rgb, Sensor(*two.world, path).image.rgb) << path;
    EXPECT_EQ(Sensor(*one.world, path).image.depth, Sensor(*two.world, path).image.depth) << path;
  }
  // They rendered something (floor, cylinders): not every pixel at the far plane.
  int near_pixels = 0;
  for (int i = 0; i < 8; ++i)
    for (float d : Sensor(*one.world, "/s" + std::to_string(i)).image.depth)
      near_pixels += d < 2.0f;
  EXPECT_GT(near_pixels, 0);
}

TEST_F(RenderingTest, BadSettingsNameTheirPlaceInTheFile) {
  const std::string base =
      "simulation: {physics: kinematic}\nobjects:\n  - {name: eye, type: vision_sensor, ";
  EXPECT_NE(ErrorOf(base + "resolution: [0, 48]}\n").find("world.yaml:3:"), std::string::npos);
  EXPECT_NE(ErrorOf(base + "resolution: [100000, 100000]}\n").find("1 to 8192"), std::string::npos);
  EXPECT_NE(ErrorOf(base + "fov_deg: 180}\n").find("fov_deg"), std::string::npos);
  EXPECT_NE(ErrorOf(base + "near: 2, far: 1}\n").find("'far'"), std::string::npos);
  EXPECT_NE(ErrorOf(base + "detectable: /nowhere}\n").find("world.yaml:3:"), std::string::npos);
  EXPECT_NE(ErrorOf(base + "projection: fisheye}\n").find("perspective"), std::string::npos);
}

// A robot's script switches its light and recolours its shape; the sensor
// sees it from the next sense phase on, and its image reaches the script.
constexpr char kLampModel[] = R"(model: lamp
objects:
  name: base
  type: dummy
  script: lamp.lua
  children:
    - {name: cube, type: shape, shape: box, size: [0.5, 0.5, 0.5], position: [2, 0, 0.25],
       color: [0.9, 0.1, 0.1]}
    - {name: sun, type: light, kind: directional, orientation_deg: [0, 90, 0], color: [1, 1, 1]}
    - {name: lamp, type: light, kind: point, position: [1, 0, 0.25], color: [1, 1, 1]}
    - {name: eye, type: vision_sensor, position: [0, 0, 0.25], resolution: [32, 24], floor: false}
)";

constexpr char kLampScript[] = R"(
function sysCall_init()
  eye = sim.getObject(':/eye')
  local img, res = sim.getVisionSensorImg(eye)
  assert(#img == res[1] * res[2] * 3 and res[1] == 32 and res[2] == 24)
  local depth = sim.getVisionSensorDepth(eye)
  assert(#depth == 32 * 24)
  local result, packet = sim.readVisionSensor(eye)
  assert(result == 0 and #packet == 15)
end
function sysCall_actuation()
  local step = math.floor(sim.getSimulationTime() / sim.getTimeStep() + 0.5)
  if step == 0 then
    sim.setLightOn(sim.getObject(':/sun'), false)
    sim.setLightOn(sim.getObject(':/lamp'), false)
  elseif step == 1 then
    sim.setLightOn(sim.getObject(':/lamp'), true)
    sim.setLightColor(sim.getObject(':/lamp'), {0, 0, 1})
    sim.setShapeColor(sim.getObject(':/cube'), {1, 1, 1})
  end
  local img = sim.getVisionSensorImg(eye)
  local i = (12 * 32 + 16) * 3
  sim.recordMetric('centre_red', img:byte(i + 1))
end
)";

TEST_F(RenderingTest, ScriptsSwitchLightsAndRecolourShapesAndTheSensorSeesIt) {
  Write("lamp.yaml", kLampModel);
  Write("lamp.lua", kLampScript);
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: lamp.yaml, position: [0, 0, 0]}]\n");
  w.world->Start();
  const auto centre = [&] {
    const uint8_t* p = Sensor(*w.world, "/lamp#0/eye").image.Pixel(16, 12);
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  const std::array<int, 3> lit = centre();
  EXPECT_GT(lit[0], 100);
  EXPECT_LT(lit[2], 60);
  w.world->Step();  // the first step's scripts switch both lights off
  w.world->Step();  // ... which the next step's sense phase sees
  const std::array<int, 3> dark = centre();
  EXPECT_LT(dark[0], lit[0] / 2) << "only the ambient light is left";
  w.world->Step();  // the lamp is on again, blue, and the cube white
  const std::array<int, 3> blue = centre();
  EXPECT_GT(blue[2], blue[0] + 60) << "a white cube under a blue lamp";
}

TEST_F(RenderingTest, ARobotMayNotRecolourAnotherRobotsShapes) {
  Write("bot.yaml",
        "model: bot\nobjects:\n  name: body\n  type: shape\n  shape: box\n  size: [0.1, 0.1, "
        "0.1]\n  script: bot.lua\n");
  Write("bot.lua",
        "function sysCall_actuation()\n"
        "  if sim.getRobotIndex() == 0 then sim.setShapeColor(sim.getObject('/bot#1'), {0, 1, 0}) "
        "end\nend\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models: [{model: bot.yaml, position: [0, 0, 0.05]}, {model: bot.yaml, position: [1, 0, "
      "0.05]}]\n");
  w.world->Start();
  try {
    w.world->Step();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("only its own robot's shapes"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("bot.lua:2"), std::string::npos) << e.what();
  }
}

TEST_F(RenderingTest, AMissingOsMesaIsAClearErrorOnlyWhenSomethingRenders) {
  // (a child process: the library is chosen once per process)
  const std::string program = SWARMSIM_BINARY;
  Write("world.yaml", kRedCube);
  const std::string command = "SWARMSIM_OSMESA_LIBRARY=/nonexistent/libOSMesa.so " + program +
                              " run " + (dir_ / "world.yaml").string() + " --steps 2 --quiet 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[512];
  while (fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_NE(output.find("libosmesa6"), std::string::npos) << output;
  // A world that renders nothing runs without it.
  Write("plain.yaml", "simulation: {physics: kinematic}\nobjects: [{name: a, type: dummy}]\n");
  const std::string plain = "SWARMSIM_OSMESA_LIBRARY=/nonexistent/libOSMesa.so " + program +
                            " run " + (dir_ / "plain.yaml").string() + " --steps 2 --quiet";
  EXPECT_EQ(std::system(plain.c_str()), 0);
}

// A mesh is drawn in its OBJ file's material colours (mtllib beside it),
// unless the world gives it a colour.
TEST_F(RenderingTest, AMeshIsDrawnInItsMaterialsColoursUnlessGivenOne) {
  Write("panel.obj",
        "mtllib panel.mtl\n"
        "v 0 -0.5 -0.25\nv 0 0 -0.25\nv 0 0 0.25\nv 0 -0.5 0.25\nv 0 0.5 -0.25\nv 0 0.5 0.25\n"
        "usemtl red\nf 1 2 3\nf 1 3 4\nusemtl green\nf 2 5 6\nf 2 6 3\n");
  Write("panel.mtl", "newmtl red\nKd 0.9 0.1 0.1\nnewmtl green\nKd 0.1 0.9 0.1\n");
  const std::string world =
      "simulation: {physics: kinematic}\n"
      "objects:\n"
      "  - {name: panel, type: shape, shape: mesh, file: panel.obj, position: [2, 0, 0.25]COLOR}\n"
      "  - {name: eye, type: vision_sensor, position: [0, 0, 0.25], resolution: [64, 48]}\n";
  std::string plain = world;
  plain.replace(plain.find("COLOR"), 5, "");
  LoadedWorld w = Load(plain);
  w.world->Start();
  const Image& image = Sensor(*w.world, "/eye").image;
  Keep(image, "mesh_materials");
  // The sensor's left (+y) sees the green half, its right (-y) the red one.
  const uint8_t* left = image.Pixel(26, 24);
  const uint8_t* right = image.Pixel(38, 24);
  EXPECT_GT(left[1], left[0] + 60) << "green";
  EXPECT_GT(right[0], right[1] + 60) << "red";
  std::string blue = world;
  blue.replace(blue.find("COLOR"), 5, ", color: [0.1, 0.1, 0.9]");
  LoadedWorld b = Load(blue);
  b.world->Start();
  EXPECT_GT(Sensor(*b.world, "/eye").image.Pixel(26, 24)[2], 120) << "the world's colour wins";
  EXPECT_GT(Sensor(*b.world, "/eye").image.Pixel(38, 24)[2], 120);
}

}  // namespace
}  // namespace swarmsim
