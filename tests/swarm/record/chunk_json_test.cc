// The JSON chunks of a recording (swarm/record/chunk_json.cc): every index
// and count of a scene checked against the scene, broken JSON and wrong types
// named in words with the chunk's byte offset, by the library and the program.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "tests/swarm/record/damaged_recordings.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;
using namespace damaged;  // NOLINT: the damaged recordings' helpers
using testing::FreshTempDir;

TEST(RecordingBoundsTest, SceneIndicesAreCheckedAgainstTheScene) {
  struct Case {
    const char* name;
    std::function<void(json&)> change;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"first", [](json& s) { s["robots"][0]["first"] = 1000000; },
       "robots[0].first is 1000000 and its count 27: ids outside the scene's 274 objects"},
      {"count", [](json& s) { s["robots"][0]["count"] = 1000000; },
       "robots[0].count is 1000000, but its template 0 has 27 objects"},
      {"object_count", [](json& s) { s["object_count"] = 1000000000000; },
       "object_count is 1000000000000, more than the"},
      {"object_count_more", [](json& s) { s["object_count"] = 275; },
       "object_count is 275, but its robots and objects have 274 ids"},
      {"template", [](json& s) { s["robots"][0]["template"] = 3; },
       "robots[0].template is 3, but the scene has 1 templates"},
      {"overlap", [](json& s) { s["robots"][1]["first"] = 0; }, "claims id 0, as does robots["},
      {"object_id_twice", [](json& s) { s["objects"][0]["id"] = 5; }, "claims id 5, as does"},
      {"object_id", [](json& s) { s["objects"][0]["id"] = 274; },
       "objects[0].id is 274, outside the scene's 274 objects"},
      {"object_parent", [](json& s) { s["objects"][0]["parent"] = 1000; },
       "objects[0].parent is 1000, outside the scene's 274 objects"},
      {"template_parent", [](json& s) { s["templates"][0]["objects"][1]["parent"] = 5; },
       "templates[0].objects[1].parent is 5, expected a whole number from -1 to 0"},
      {"index_twice", [](json& s) { s["robots"][2]["index"] = 1; }, "two robots have the index 1"},
      {"negative_first", [](json& s) { s["robots"][0]["first"] = -1; },
       "robots[0].first is -1, expected a whole number from 0 up"},
      {"fraction", [](json& s) { s["robots"][0]["first"] = 1.5; }, "robots[0].first is 1.5"},
      {"no_first", [](json& s) { s["robots"][0].erase("first"); }, "robots[0] has no first"},
      {"robots_map", [](json& s) { s["robots"] = json::object(); },
       "robots is a map, expected a list"},
      {"count_text", [](json& s) { s["object_count"] = "many"; },
       "object_count is \"many\", expected a whole number"},
      {"mesh", [](json& s) { s["objects"][0]["mesh"] = 0; },
       "objects[0].mesh is 0, but the scene has 0 meshes"},
      {"triangles",
       [](json& s) {
         s["meshes"] = json::array({{{"vertices", {0, 0, 0}}, {"triangles", {0, 0, 1}}}});
       },
       "meshes[0].triangles names vertex 1, but it has 1 vertices"},
      {"deep",
       [](json& s) {
         json deep = json::array();
         for (int i = 0; i < 100; ++i) deep = json::array({deep});
         s["robots"][0]["parameters"]["x"] = deep;
       },
       "is nested deeper than 64 levels"},
  };
  for (const Case& c : cases) {
    const fs::path dir = WriteRun(c.name, WithScene(c.change));
    const std::string prefix =
        (dir / kRecordingFileName).string() + " is corrupt: chunk 2 at byte 332 (scene): ";
    std::string error;
    try {
      ScanRecording(dir);
    } catch (const Error& e) {
      error = e.what();
    }
    EXPECT_EQ(error.rfind(prefix, 0), 0u) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
    EXPECT_EQ(ReadError(dir), error) << c.name;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
}

TEST(RecordingBoundsTest, BrokenJsonAndWrongTypesAreNamedInWords) {
  // Header, scene and end chunks whose JSON is broken or of the wrong type.
  std::vector<Chunk> original = ChunksOf(kDiffusion);
  const auto with = [&](size_t index, std::string payload) {
    std::vector<Chunk> chunks = original;
    chunks[index].payload = std::move(payload);
    return Encode(chunks);
  };
  json header = json::parse(original[0].payload);
  const size_t end = original.size() - 1;
  ASSERT_EQ(original[end].kind, static_cast<uint8_t>(ChunkKind::kEnd));
  struct Case {
    const char* name;
    std::string bytes;
    std::string expected;
  };
  std::vector<Case> cases;
  json paint = header;
  paint["paint"] = {{"width", "x"}, {"height", 10}};
  cases.push_back({"paint_width", with(0, paint.dump()),
                   "(header): paint.width is \"x\", expected a whole number from 1"});
  paint["paint"] = {{"width", 100000}, {"height", 100000}};
  cases.push_back({"paint_size", with(0, paint.dump()),
                   "(header): paint is 100000 x 100000 cells, more than the 67108864"});
  json metrics = header;
  metrics["metrics"] = {1, 2};
  cases.push_back(
      {"metrics", with(0, metrics.dump()), "(header): metrics[0] is 1, expected a metric's name"});
  cases.push_back({"header_text", with(0, original[0].payload.substr(0, 50)),
                   "(header): its JSON text is broken at byte"});
  cases.push_back({"scene_text", with(1, original[1].payload.substr(0, 100)),
                   "(scene): its JSON text is broken at byte"});
  cases.push_back({"scene_list", with(1, "[1, 2]"), "(scene): the top level is a list"});
  cases.push_back({"end_status", with(end, R"({"steps": 30, "status": 5})"),
                   "(end): status is 5, expected a string"});
  cases.push_back({"end_text", with(end, "{\"status\": \"ok"), "(end): its JSON text is broken"});
  for (const Case& c : cases) {
    const fs::path dir = WriteRun(c.name, c.bytes);
    const std::string error = ReadError(dir);
    EXPECT_NE(error.find(" is corrupt: chunk "), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
    ExpectUsersMessage(error, dir);
    fs::remove_all(dir);
  }
  // A format name of the wrong type: not a recording.
  json format = header;
  format["format"] = 5;
  const fs::path dir = WriteRun("format", with(0, format.dump()));
  EXPECT_NE(ReadError(dir).find("is not a swarmsim recording"), std::string::npos)
      << ReadError(dir);
  fs::remove_all(dir);
}

TEST(RecordingBoundsCliTest, RecordInfoAndViewRefuseASceneThatPointsPastItsObjects) {
  for (const char* field : {"first", "count"}) {
    const fs::path dir = WriteRun(std::string("cli_") + field,
                                  WithScene([&](json& s) { s["robots"][0][field] = 1000000; }));
    const std::string where = (dir / kRecordingFileName).string() +
                              " is corrupt: chunk 2 at byte 332 (scene): robots[0]." + field +
                              " is 1000000";
    const auto info = Swarmsim("record-info " + dir.string());
    EXPECT_EQ(info.exit_code, 2) << info.output;
    EXPECT_NE(info.output.find("error: " + where), std::string::npos) << info.output;
    const auto exported =
        Swarmsim("view " + dir.string() + " --export " + (dir / "x.html").string());
    EXPECT_EQ(exported.exit_code, 2) << exported.output;
    EXPECT_NE(exported.output.find("error: " + where), std::string::npos) << exported.output;
    EXPECT_FALSE(fs::exists(dir / "x.html"));
    const auto served = Swarmsim("view " + dir.string() + " --port 0");
    EXPECT_EQ(served.exit_code, 2) << served.output;
    EXPECT_NE(served.output.find("error: " + where), std::string::npos) << served.output;
    fs::remove_all(dir);
  }
}

}  // namespace
}  // namespace swarmsim::record
