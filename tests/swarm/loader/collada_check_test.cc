// The checks on a COLLADA file before assimp reads it (swarm/loader/collada_check.cc,
// declared in mesh_check.h): each rule refuses its case with the file, the
// line and what is wrong, and a good file reads the same through them (unit,
// node transform, colour).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/mesh.h"
#include "swarm/loader/mesh_check.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/meshes";

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kCube = ReadAll(kMeshes / "cube.dae");
const std::string kTriangles =
    "<p>0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 1 2 6 1 6 5 2 3 7 2 7 6 3 0 4 3 4 7</p>";

// The cube with `from` replaced by `to` (which must be there).
std::string Cube(const std::string& from, const std::string& to) {
  std::string text = kCube;
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string ColladaError(const std::string& text) {
  try {
    CheckColladaBytes(text, "part.dae");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(MeshCheckTest, ColladaPrimitivesAgreeWithTheirCounts) {
  EXPECT_EQ(ColladaError(kCube), "no error");
  EXPECT_EQ(ColladaError(Cube(kTriangles, kTriangles + kTriangles)),
            "part.dae:29: <triangles> count=\"12\" needs exactly one <p>, not 2 (one <triangles> "
            "element per <p>)");
  EXPECT_EQ(ColladaError(Cube("<p>0 2 1 ", "<p>0 2 ")),
            "part.dae:31: <p> holds 35 indices, but <triangles> count=\"12\" (line 29) with 1 "
            "index per corner need 36");
  EXPECT_EQ(ColladaError(Cube("count=\"12\"", "count=\"twelve\"")),
            "part.dae:29: <triangles count=\"twelve\"> must be a non-negative integer of at most "
            "4,294,967,295");
  // A polylist's <vcount> comes first, one value per polygon.
  std::string good = Cube("<triangles count=\"12\"", "<polylist count=\"12\"");
  good.replace(good.find("</triangles>"), 12, "</polylist>");
  std::string vcount = "<vcount>";
  for (int k = 0; k < 12; ++k) vcount += "3 ";
  vcount += "</vcount>";
  std::string after = good;
  good.replace(good.find(kTriangles), 0, vcount);
  after.replace(after.find(kTriangles) + kTriangles.size(), 0, vcount);
  EXPECT_EQ(ColladaError(good), "no error");
  EXPECT_EQ(ColladaError(after),
            "part.dae:31: <polylist> (line 29) needs its <vcount> before its <p>");
  // A <p> needs a VERTEX input before it; its offsets are small.
  EXPECT_EQ(ColladaError(Cube("semantic=\"VERTEX\"", "semantic=\"NORMAL\"")),
            "part.dae:31: <triangles> (line 29) has no <input semantic=\"VERTEX\"> before its <p>");
  EXPECT_EQ(ColladaError(Cube("offset=\"0\"", "offset=\"4000000000\"")),
            "part.dae:30: <input offset=\"4000000000\"> must be a non-negative integer of at most "
            "63");
  // Strips and polygons: one <p> each, at least 3 corners.
  std::string strip = Cube("<triangles count=\"12\"", "<tristrips count=\"0\"");
  strip.replace(strip.find("</triangles>"), 12, "</tristrips>");
  EXPECT_EQ(ColladaError(strip),
            "part.dae:29: <tristrips> count=\"0\" has 1 <p> (one per strip or fan)");
}

// A polygon of more than kMaxFaceCorners corners, in a <polylist> or a
// <polygons>, is refused before assimp splits it (quadratic time).
TEST(MeshCheckTest, ColladaFacesHaveAtMostAThousandCorners) {
  const auto polygon = [](int corners) {
    std::string p = "<p>";
    for (int k = 0; k < corners; ++k) p += std::to_string(k % 8) + " ";
    return p + "</p>";
  };
  std::string list = Cube("<triangles count=\"12\"", "<polylist count=\"1\"");
  list.replace(list.find("</triangles>"), 12, "</polylist>");
  std::string fits = list, big = list;
  fits.replace(fits.find(kTriangles), kTriangles.size(), "<vcount>1000</vcount>" + polygon(1000));
  big.replace(big.find(kTriangles), kTriangles.size(), "<vcount>60000</vcount>" + polygon(60000));
  EXPECT_EQ(ColladaError(fits), "no error");
  EXPECT_EQ(ColladaError(big),
            "part.dae:31: <vcount>: a face of 60,000 corners; at most 1,000 (split a larger "
            "polygon into smaller faces)");
  std::string polygons = Cube("<triangles count=\"12\"", "<polygons count=\"1\"");
  polygons.replace(polygons.find("</triangles>"), 12, "</polygons>");
  std::string fits_p = polygons, big_p = polygons;
  fits_p.replace(fits_p.find(kTriangles), kTriangles.size(), polygon(1000));
  big_p.replace(big_p.find(kTriangles), kTriangles.size(), polygon(1001));
  EXPECT_EQ(ColladaError(fits_p), "no error");
  EXPECT_EQ(ColladaError(big_p),
            "part.dae:31: <p> of <polygons>: a face of 1,001 corners; at most 1,000 (split a "
            "larger polygon into smaller faces)");
}

TEST(MeshCheckTest, ColladaIndicesAreIntegersWithinTheirSources) {
  for (const std::string token : {".NaN", "inf", "1e-320", "0x7fffffff", "-1", "+1", "2147483648"})
    EXPECT_EQ(ColladaError(Cube("<p>0 2 1", "<p>0 " + token + " 1")),
              "part.dae:31: <p> index '" + token + "' is not a non-negative integer");
  EXPECT_EQ(ColladaError(Cube("<p>0 2 1", "<p>0 8 1")),
            "part.dae:31: <p> index 8 (input VERTEX) is beyond the 8 entries of 'cube-vtx'");
  // A comment or an element inside <p> does not hide a token from the check.
  EXPECT_EQ(ColladaError(Cube("<p>0 2 1", "<p>0 2<!-- x --> .NaN")),
            "part.dae:31: <p> index '.NaN' is not a non-negative integer");
}

TEST(MeshCheckTest, ColladaArraysAndAccessorsHoldWhatTheySay) {
  EXPECT_EQ(ColladaError(Cube("count=\"24\"", "count=\"4000000000\"")),
            "part.dae:21: <float_array count=\"4000000000\"> holds only 24 values");
  EXPECT_EQ(ColladaError(Cube("count=\"24\">-0.5", "count=\"24\">nan")),
            "part.dae:21: <float_array id='cube-pos-array'> value 'nan' is not a finite number");
  EXPECT_EQ(ColladaError(Cube("count=\"8\" stride=\"3\"", "count=\"9\" stride=\"3\"")),
            "part.dae:23: <accessor count=\"9\" stride=\"3\" offset=\"0\"> reads 27 numbers of "
            "array 'cube-pos-array' (line 21), which has 24");
  EXPECT_EQ(ColladaError(Cube("count=\"8\" stride=\"3\"", "count=\"-1\" stride=\"3\"")),
            "part.dae:23: <accessor count=\"-1\"> must be a non-negative integer of at most "
            "2,147,483,647");
}

// assimp reads numbers separated by space, tab, CR, LF and form feed; at a
// vertical tab its <p> loop appended zeros until 1.6 GB (a fuzz finding,
// tests/data/fuzz/mesh_dae/crashes/oom-vertical-tab-in-p.dae).
TEST(MeshCheckTest, ColladaNumbersAreSeparatedAsAssimpReadsThem) {
  EXPECT_EQ(ColladaError(Cube("<p>0 2 1 0", "<p>0\v2\v1 0")),
            "part.dae:31"
            ": <p> separates its numbers with a vertical tab (0x0B); use spaces");
  EXPECT_EQ(ColladaError(Cube("count=\"24\">-0.5", "count=\"24\">\v-0.5")),
            "part.dae:21: <float_array> separates its numbers with a vertical tab (0x0B); use "
            "spaces");
  EXPECT_EQ(ColladaError(Cube("<p>0 2 1 0", "<p>0\t2\r\n1\f0")), "no error");
  const fs::path finding =
      fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/fuzz/mesh_dae/crashes/oom-vertical-tab-in-p.dae";
  EXPECT_EQ(ColladaError(ReadAll(finding)),
            "part.dae:7: <p> separates its numbers with a vertical tab (0x0B); use spaces");
}

TEST(MeshCheckTest, ColladaNodesNeitherCycleNorExplode) {
  EXPECT_EQ(
      ColladaError(Cube("<node id=\"cube\">", "<node id=\"cube\"><instance_node url=\"#cube\"/>")),
      "part.dae:38: node 'cube' contains itself (through <instance_node>)");
  // 2^20 instances of the cube through 20 library nodes, each twice the next.
  std::string nodes = "<library_nodes>";
  for (int k = 0; k < 20; ++k)
    nodes += "<node id=\"n" + std::to_string(k) + "\"><instance_node url=\"#n" +
             std::to_string(k + 1) + "\"/><instance_node url=\"#n" + std::to_string(k + 1) +
             "\"/></node>";
  nodes += "<node id=\"n20\"><instance_geometry url=\"#cube-mesh\"/></node></library_nodes>";
  const std::string e =
      ColladaError(Cube("<library_visual_scenes>", nodes + "<library_visual_scenes>"));
  EXPECT_NE(e.find("the node hierarchy makes more than 100,000 nodes"), std::string::npos) << e;
  // A chain of instances deeper than assimp's recursion may go.
  nodes = "<library_nodes>";
  for (int k = 0; k < 300; ++k)
    nodes += "<node id=\"c" + std::to_string(k) + "\"><instance_node url=\"#c" +
             std::to_string(k + 1) + "\"/></node>";
  nodes += "<node id=\"c300\"/></library_nodes>";
  EXPECT_NE(ColladaError(Cube("<library_visual_scenes>", nodes + "<library_visual_scenes>"))
                .find("more than 256 levels deep"),
            std::string::npos);
}

// What assimp resolves by id names its line when it resolves to nothing
// (assimp's own "Unable to resolve library reference" named none), as do a
// unit that is not a positive number, a DOCTYPE's declarations and an
// entity tinyxml2 would keep as text.
TEST(MeshCheckTest, ColladaReferencesAndEntitiesNameTheirLine) {
  EXPECT_EQ(ColladaError(Cube("source=\"#cube-vtx\"", "source=\"#nowhere\"")),
            "part.dae:30: <input semantic=\"VERTEX\" source=\"#nowhere\"> must name its "
            "<mesh>'s <vertices> (id 'cube-vtx')");
  EXPECT_EQ(ColladaError(Cube("source=\"#cube-pos\"/>", "source=\"#nowhere\"/>")),
            "part.dae:28: <input semantic=\"POSITION\" source=\"#nowhere\">: the file's "
            "geometries have no <source> with id 'nowhere'");
  EXPECT_EQ(ColladaError(Cube("source=\"#cube-pos-array\"", "source=\"#nowhere\"")),
            "part.dae:23: <accessor source=\"#nowhere\">: the file's geometries have no array "
            "with id 'nowhere'");
  EXPECT_EQ(ColladaError(Cube("url=\"#scene\"", "url=\"#nowhere\"")),
            "part.dae:48: <instance_visual_scene url=\"#nowhere\">: the file has no "
            "<visual_scene> with id 'nowhere'");
  for (const std::string meter : {"abc", "0", "-1", "nan"})
    EXPECT_EQ(
        ColladaError(Cube("meter=\"0.01\"", "meter=\"" + meter + "\"")),
        "part.dae:4: <unit meter=\"" + meter + "\"> must be a positive number (metres per unit)");
  EXPECT_EQ(ColladaError(Cube("<COLLADA", "<!DOCTYPE COLLADA [<!ENTITY h \"0.5\">]>\n<COLLADA")),
            "part.dae:3: a <!DOCTYPE> with declarations ([...]): the COLLADA reader applies no "
            "DTD, so its entities and defaults would be lost; write the values out and remove "
            "them");
  EXPECT_EQ(ColladaError(Cube("-0.5 -0.5 -0.5 0.5", "-0.5 -0.5 &h; 0.5")),
            "part.dae:21: '&h;' refers to an entity the COLLADA reader does not know (it knows "
            "XML's own: &lt; &gt; &amp; &quot; &apos; and &#...;); write the value out");
}

TEST(MeshCheckTest, ColladaIsWellFormedXmlOfAtMostAMillionElements) {
  EXPECT_NE(ColladaError(kCube.substr(0, 600)).find("part.dae:"), std::string::npos);
  EXPECT_NE(ColladaError(kCube.substr(0, 600)).find("malformed XML"), std::string::npos);
  EXPECT_EQ(ColladaError("<robot/>"),
            "part.dae:1: a COLLADA file's root element must be <COLLADA>, not <robot>");
  std::string many = "<COLLADA>";
  for (int k = 0; k <= kMaxColladaElements; ++k) many += "<a/>";
  EXPECT_EQ(ColladaError(many + "</COLLADA>"),
            "part.dae: has more than 1,000,000 XML elements, the limit for a COLLADA file");
}

TEST(MeshCheckTest, ColladaForAssimpKeepsGeometryAndDropsTheRest) {
  std::string text = Cube("<library_geometries>",
                          "<library_animations><animation/></library_animations>"
                          "<library_controllers><controller id=\"skin\"><skin "
                          "source=\"#cube-mesh\"/></controller></library_controllers>"
                          "<library_geometries>");
  text.replace(text.find("<instance_geometry url=\"#cube-mesh\">"), 36,
               "<instance_controller url=\"#skin\">");
  text.replace(text.find("</instance_geometry>"), 20, "</instance_controller>");
  const std::string out = CheckColladaBytes(text, "part.dae");
  EXPECT_EQ(out.find("library_animations"), std::string::npos);
  EXPECT_EQ(out.find("library_controllers"), std::string::npos);
  EXPECT_EQ(out.find("<!--"), std::string::npos);
  EXPECT_NE(out.find("<instance_geometry url=\"#cube-mesh\">"), std::string::npos) << out;
  EXPECT_NE(out.find(kTriangles), std::string::npos);
}

// Through the loader: a COLLADA file's unit, node transform and material
// colour survive the checks; a scale that takes a vertex past the
// coordinate limit is an error naming the file.
TEST(MeshCheckTest, LoadedColladaKeepsUnitTransformAndColour) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_mesh_check_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(kMeshes / "cube.dae", dir / "cube.dae", fs::copy_options::overwrite_existing);
  const auto world = [&](const std::string& scale) {
    std::ofstream(dir / "world.yaml")
        << "simulation: {physics: kinematic, time_step: 0.1}\n"
           "obstacles:\n  - {name: part, shape: mesh, file: cube.dae, scale: "
        << scale << "}\n";
    return dir / "world.yaml";
  };
  {
    const LoadedWorld w = LoadWorld(world("[1, 1, 1]"), {}, registry);
    const ShapeData& part = w.world->scene().shape(w.world->scene().FindObject("/part"));
    ASSERT_TRUE(part.mesh);
    EXPECT_EQ(part.mesh->triangles().size(), 12u);
    EXPECT_NEAR(part.mesh->lo().z, 0.015, 1e-8);  // centimetres, moved 2 cm up (floats)
    EXPECT_NEAR(part.mesh->hi().z, 0.025, 1e-8);
    EXPECT_NEAR(part.mesh->hi().x, 0.005, 1e-8);
    ASSERT_EQ(part.mesh->colors().size(), 12u);
    EXPECT_NEAR(part.mesh->colors()[0].x, 0.8, 1e-6);
    EXPECT_NEAR(part.mesh->colors()[0].y, 0.1, 1e-6);
  }
  try {
    LoadWorld(world("[1, 1, 1e8]"), {}, registry);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("world.yaml:3:"), std::string::npos) << text;
    EXPECT_NE(text.find(": mesh file 'cube.dae' has a vertex scaled at ("), std::string::npos)
        << text;
    EXPECT_NE(text.find(" m; coordinates are at most 1e+06 m"), std::string::npos) << text;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim::loader
