// Meshes in the viewer page (headless Chromium), as a user sees them: the
// recording's embedded meshes drawn as their triangles (one geometry per
// asset, instanced over its copies) in their own colours or the recorded
// ones, not as boxes; past the triangle budget (the page's mesh_budget)
// simplified, or boxes, as the status line says; an imported URDF arm (the
// Panda of ../shared/urdf, when it is there) with its files' triangles and
// material colours.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "swarm/record/reader.h"
#include "tests/shared_urdf.h"
#include "tests/swarm/run_program.h"
#include "tests/swarm/viewer/browser.h"

namespace swarmsim::testing {
namespace {
namespace fs = std::filesystem;

// A UV sphere of radius 0.3 m, 32 segments by 16 stacks (960 triangles,
// counter-clockwise seen from outside), its upper half in material `top`
// (red) and its lower half in `bottom` (blue).
constexpr int kSegments = 32, kStacks = 16;
constexpr int kBallTriangles = 2 * kSegments + 2 * kSegments * (kStacks - 2);

void WriteBall(const fs::path& dir) {
  std::ofstream(dir / "ball.mtl") << "newmtl top\nKd 1 0 0\nnewmtl bottom\nKd 0 0 1\n";
  std::ofstream obj(dir / "ball.obj");
  obj << "mtllib ball.mtl\n";
  // Vertex 1: the north pole; rings 1..kStacks-1; the south pole last.
  obj << "v 0 0 0.3\n";
  for (int j = 1; j < kStacks; ++j)
    for (int i = 0; i < kSegments; ++i) {
      const double t = M_PI * j / kStacks, p = 2 * M_PI * i / kSegments;
      obj << "v " << 0.3 * std::sin(t) * std::cos(p) << ' ' << 0.3 * std::sin(t) * std::sin(p)
          << ' ' << 0.3 * std::cos(t) << '\n';
    }
  const int south = 2 + (kStacks - 1) * kSegments;
  obj << "v 0 0 -0.3\n";
  const auto ring = [](int j, int i) { return 2 + (j - 1) * kSegments + (i % kSegments); };
  for (int j = 0; j < kStacks; ++j) {
    obj << (j < kStacks / 2 ? "usemtl top\n" : "usemtl bottom\n");
    for (int i = 0; i < kSegments; ++i) {
      if (j == 0) {
        obj << "f 1 " << ring(1, i) << ' ' << ring(1, i + 1) << '\n';
      } else if (j == kStacks - 1) {
        obj << "f " << ring(j, i) << ' ' << south << ' ' << ring(j, i + 1) << '\n';
      } else {
        obj << "f " << ring(j, i) << ' ' << ring(j + 1, i) << ' ' << ring(j + 1, i + 1) << '\n';
        obj << "f " << ring(j, i) << ' ' << ring(j + 1, i + 1) << ' ' << ring(j, i + 1) << '\n';
      }
    }
  }
}

// The scene chunk of a recording, read with swarmsim's own reader.
json SceneOf(const fs::path& folder) {
  record::RecordingPlayer player(folder / "recording.swrec");
  EXPECT_TRUE(player.Next());
  return json::parse(player.scene_json());
}

// sRGB 0xRRGGBB of an RGB 0..1 triple, as the recording rounds it to bytes.
int Hex(const json& rgb) {
  int hex = 0;
  for (int k = 0; k < 3; ++k)
    hex =
        hex << 8 | static_cast<int>(std::lround(std::clamp(rgb[k].get<double>(), 0.0, 1.0) * 255));
  return hex;
}

// Two balls in their own colours (red on top, blue below) and one in the
// colour its world gives it (green), all one mesh file.
class ViewerMeshTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!BrowserMissing().empty()) return;
    dir_ = new fs::path(FreshTempDir("viewer_mesh", "balls"));
    fs::create_directories(*dir_);
    WriteBall(*dir_);
    std::ofstream(*dir_ / "world.yaml")
        << "simulation: {physics: kinematic, time_step: 0.1, seed: 1, duration: 0.5}\n"
           "arena: {size: 4, wall_thickness: 0.05, wall_height: 0.05}\n"
           "objects:\n"
           "  - {name: ball_a, type: shape, shape: mesh, file: ball.obj,"
           " position: [-1, 0.8, 0.3]}\n"
           "  - {name: ball_b, type: shape, shape: mesh, file: ball.obj,"
           " position: [-1, -0.8, 0.3]}\n"
           "  - {name: green, type: shape, shape: mesh, file: ball.obj, position: [1, 0, 0.3],"
           " color: [0, 1, 0]}\n";
    const CommandResult run = RunProgram("run " + (*dir_ / "world.yaml").string() +
                                         " --quiet --record --out " + (*dir_ / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  static void TearDownTestSuite() {
    if (dir_) fs::remove_all(*dir_);
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (const std::string missing = BrowserMissing(); !missing.empty()) GTEST_SKIP() << missing;
  }

  // Opens the page with `query` (after the '?'), waits for it, views from above.
  static void OpenAt(Browser* browser, ViewServer* server, const std::string& query) {
    browser->Open(server->Address() + (query.empty() ? "" : "?" + query));
    ASSERT_EQ(browser->WaitForViewer(), "");
    browser->Run("swarmsimViewer.topDown(); swarmsimViewer.setRecord(0);");
  }
  // The screenshot's colour at the page pixel world point (x, y, z) projects to.
  static std::array<int, 3> ColourAt(Browser* browser, const Image& image, double x, double y,
                                     double z) {
    const json p = browser->Run("return swarmsimViewer.project(" + std::to_string(x) + ", " +
                                std::to_string(y) + ", " + std::to_string(z) + ");");
    const int px = std::clamp(static_cast<int>(p["x"].get<double>()), 0, image.width - 1);
    const int py = std::clamp(static_cast<int>(p["y"].get<double>()), 0, image.height - 1);
    const uint8_t* c = image.At(px, py);
    return {c[0], c[1], c[2]};
  }
  static bool IsGreen(const std::array<int, 3>& c) { return c[1] > 150 && c[0] < 90 && c[2] < 90; }
  static bool IsRed(const std::array<int, 3>& c) { return c[0] > 150 && c[1] < 90 && c[2] < 90; }

  static fs::path* dir_;
};
fs::path* ViewerMeshTest::dir_ = nullptr;

TEST_F(ViewerMeshTest, DrawsTheRecordedMeshesInTheirColoursNotTheirBoxes) {
  // What the recording holds: one mesh asset of 960 triangles (written
  // above), used by the three balls.
  const json scene = SceneOf(*dir_ / "out");
  ASSERT_EQ(scene["meshes"].size(), 1u);
  ASSERT_EQ(scene["meshes"][0]["triangles"].size(), 3u * kBallTriangles);

  ViewServer server((*dir_ / "out").string(), (*dir_ / "server.log").string());
  Browser browser;
  OpenAt(&browser, &server, "");
  const json meshes = browser.Run("return swarmsimViewer.meshes();");
  EXPECT_EQ(meshes["triangles"], 3 * kBallTriangles) << meshes.dump();
  EXPECT_EQ(meshes["drawnTriangles"], 3 * kBallTriangles);
  // Two groups of one geometry each: the balls in the file's colours (two
  // instances, a material per colour) and the green one (its recorded colour).
  ASSERT_EQ(meshes["groups"].size(), 2u) << meshes.dump();
  std::map<int, json> by_instances;
  for (const json& g : meshes["groups"]) by_instances[g["instances"].get<int>()] = g;
  ASSERT_TRUE(by_instances.contains(2) && by_instances.contains(1)) << meshes.dump();
  for (const json& g : meshes["groups"]) {
    EXPECT_EQ(g["asBox"], false);
    EXPECT_EQ(g["simplified"], false);
    EXPECT_EQ(g["triangles"], kBallTriangles);
    EXPECT_EQ(g["geometryTriangles"], kBallTriangles);
  }
  EXPECT_EQ(std::set<int>(by_instances[2]["colors"].begin(), by_instances[2]["colors"].end()),
            (std::set<int>{0xff0000, 0x0000ff}));
  EXPECT_TRUE(by_instances[1]["colors"].is_null());
  EXPECT_EQ(by_instances[1]["instanceColors"], json::array({0x00ff00}));
  const std::string status = browser.Run("return swarmsimViewer.status;");
  EXPECT_NE(status.find("meshes: 2880 triangles"), std::string::npos) << status;

  // The picture from above: the green ball's centre is green, the corner of
  // its bounding box (outside the sphere) is not; ball_a shows its red top.
  const Image image = browser.Screenshot();
  ASSERT_GT(image.width, 0);
  EXPECT_TRUE(IsGreen(ColourAt(&browser, image, 1, 0, 0.6)));
  EXPECT_FALSE(IsGreen(ColourAt(&browser, image, 1.27, 0.27, 0.6)));
  EXPECT_TRUE(IsRed(ColourAt(&browser, image, -1, 0.8, 0.6)));
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
}

TEST_F(ViewerMeshTest, PastTheBudgetMeshesAreSimplifiedOrBoxesAsTheStatusLineSays) {
  ViewServer server((*dir_ / "out").string(), (*dir_ / "server_budget.log").string());
  {
    // 2880 triangles > 1000: each drawn with its share (1000 / 2880 of its
    // 960), at least 12, still a sphere from above.
    Browser browser;
    OpenAt(&browser, &server, "mesh_budget=1000");
    const json meshes = browser.Run("return swarmsimViewer.meshes();");
    EXPECT_LE(meshes["drawnTriangles"].get<int>(), 1000) << meshes.dump();
    for (const json& g : meshes["groups"]) {
      EXPECT_EQ(g["simplified"], true) << g.dump();
      EXPECT_LE(g["triangles"].get<int>(), kBallTriangles * 1000 / 2880) << g.dump();
      EXPECT_GE(g["triangles"].get<int>(), 12) << g.dump();
    }
    const std::string status = browser.Run("return swarmsimViewer.status;");
    EXPECT_NE(status.find("meshes simplified to"), std::string::npos) << status;
    EXPECT_NE(status.find("2880 triangles > budget 1000"), std::string::npos) << status;
    const Image image = browser.Screenshot();
    EXPECT_TRUE(IsGreen(ColourAt(&browser, image, 1, 0, 0.6)));
    EXPECT_FALSE(IsGreen(ColourAt(&browser, image, 1.27, 0.27, 0.6)));
    EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  }
  {
    // A budget of 0: every mesh is its bounding box, and the box's corner is green.
    Browser browser;
    OpenAt(&browser, &server, "mesh_budget=0");
    const json meshes = browser.Run("return swarmsimViewer.meshes();");
    for (const json& g : meshes["groups"]) EXPECT_EQ(g["asBox"], true) << g.dump();
    EXPECT_EQ(meshes["drawnTriangles"], 0);
    const std::string status = browser.Run("return swarmsimViewer.status;");
    EXPECT_NE(status.find("meshes as boxes: 2880 triangles > budget 0"), std::string::npos)
        << status;
    const Image image = browser.Screenshot();
    EXPECT_TRUE(IsGreen(ColourAt(&browser, image, 1, 0, 0.6)));
    EXPECT_TRUE(IsGreen(ColourAt(&browser, image, 1.27, 0.27, 0.6)));
    EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  }
  {
    // A budget that is not a count is named, and the default (1 M) applies.
    Browser browser;
    OpenAt(&browser, &server, "mesh_budget=lots");
    const std::string status = browser.Run("return swarmsimViewer.status;");
    EXPECT_NE(status.find("mesh_budget 'lots' is not a triangle count"), std::string::npos)
        << status;
    EXPECT_EQ(browser.Run("return swarmsimViewer.meshes().drawnTriangles;"), 3 * kBallTriangles);
  }
}

// `swarmsim view --mesh-budget N` sets the page's budget, served and
// exported; the URL's mesh_budget still overrides it.
TEST_F(ViewerMeshTest, TheViewCommandsMeshBudgetSetsThePagesAndTheUrlOverridesIt) {
  ViewServer server((*dir_ / "out").string(), (*dir_ / "server_flag.log").string(),
                    {"--mesh-budget", "0"});
  ASSERT_FALSE(server.Address().empty()) << server.Output();
  {
    Browser browser;
    OpenAt(&browser, &server, "");
    const std::string status = browser.Run("return swarmsimViewer.status;");
    EXPECT_NE(status.find("meshes as boxes: 2880 triangles > budget 0"), std::string::npos)
        << status;
  }
  {
    Browser browser;
    OpenAt(&browser, &server, "mesh_budget=5k");
    EXPECT_EQ(browser.Run("return swarmsimViewer.meshes().drawnTriangles;"), 3 * kBallTriangles);
  }
  const fs::path html = *dir_ / "boxes.html";
  const CommandResult exported = RunProgram("view " + (*dir_ / "out").string() + " --export " +
                                            html.string() + " --mesh-budget 1000");
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  Browser browser;
  browser.Open("file://" + html.string());
  ASSERT_EQ(browser.WaitForViewer(), "");
  const std::string status = browser.Run("return swarmsimViewer.status;");
  EXPECT_NE(status.find("2880 triangles > budget 1000"), std::string::npos) << status;
  // Not a count: the program says so.
  const CommandResult bad = RunProgram("view " + (*dir_ / "out").string() + " --export " +
                                       html.string() + " --mesh-budget lots");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--mesh-budget"), std::string::npos) << bad.output;
}

// Three Pandas imported from their URDF: every visual mesh file's triangles
// drawn (the collision meshes not), and the COLLADA visuals in their
// materials' colours (white and dark grey).
TEST(ViewerMeshUrdfTest, DrawsAnImportedArmsMeshesWithTheirTrianglesAndMaterials) {
  if (const std::string missing = BrowserMissing(); !missing.empty()) GTEST_SKIP() << missing;
  const std::string urdf = testing::SharedUrdf();
  if (urdf.empty())
    GTEST_SKIP() << "the shared URDF robots (../shared/urdf) are not here; set SWARMSIM_URDF_DIR";
  const fs::path dir = FreshTempDir("viewer_mesh", "panda");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: 0.02, seed: 1, duration: 0.1}\n"
         "models:\n  - model: "
      << urdf << "/panda/example-robot-data/robots/panda_description/urdf/panda.urdf\n"
      << "    count: 3\n"
         "    distribute: {region: {min: [-1.5, -1], max: [1.5, 1]}, clearance: 0.5}\n";
  const CommandResult run = RunProgram("run " + (dir / "world.yaml").string() +
                                       " --quiet --record --out " + (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;

  // What the recording says: per asset, its triangles, its distinct colours
  // (bytes, as drawn), and how many objects use it in their own colours.
  const json scene = SceneOf(dir / "out");
  const json& assets = scene["meshes"];
  // The 10 COLLADA visuals (finger twice); the 9 STL collision meshes lie
  // behind them and are not drawn, so not recorded.
  ASSERT_GE(assets.size(), 10u);
  for (const json& asset : assets)
    EXPECT_EQ(asset["file"].get<std::string>().find(".stl"), std::string::npos) << asset["file"];
  int64_t total = 0;
  for (const json& robot : scene["robots"])
    for (const json& o : scene["templates"][robot["template"].get<int>()]["objects"])
      if (o.contains("mesh")) total += assets[o["mesh"].get<int>()]["triangles"].size() / 3;
  EXPECT_GT(total, 3 * 100000) << "the Panda's visual meshes hold over 100,000 triangles";

  ViewServer server((dir / "out").string(), (dir / "server.log").string());
  Browser browser;
  browser.Open(server.Address() + "?mesh_budget=2M");
  ASSERT_EQ(browser.WaitForViewer(30), "");
  const json meshes = browser.Run("return swarmsimViewer.meshes();");
  EXPECT_EQ(meshes["triangles"], total);
  EXPECT_EQ(meshes["drawnTriangles"], total);
  int multicoloured = 0;
  for (const json& g : meshes["groups"]) {
    const json& asset = assets[g["asset"].get<int>()];
    EXPECT_EQ(g["asBox"], false) << g.dump();
    EXPECT_EQ(g["triangles"], asset["triangles"].size() / 3) << asset["file"];
    EXPECT_EQ(g["geometryTriangles"], asset["triangles"].size() / 3) << asset["file"];
    if (g["colors"].is_null()) continue;
    std::set<int> recorded;
    const json& c = asset["colors"];
    for (size_t t = 0; t + 2 < c.size(); t += 3)
      recorded.insert(Hex(json::array({c[t], c[t + 1], c[t + 2]})));
    EXPECT_EQ(std::set<int>(g["colors"].begin(), g["colors"].end()), recorded) << asset["file"];
    if (recorded.size() > 1) ++multicoloured;
  }
  EXPECT_GE(multicoloured, 5) << "links drawn in their files' several materials";
  const std::string status = browser.Run("return swarmsimViewer.status;");
  const std::string text = std::to_string((total + 500) / 1000) + " k";  // "405 k"
  EXPECT_NE(status.find("meshes: " + text + " triangles"), std::string::npos) << status;
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim::testing
