// Mesh files that assimp 5.2 does not survive (issue 26), through the
// program: `swarmsim run` ends with exit 2, a message naming the mesh file
// and its line, and an --out folder whose summary.json says so; never an
// abort, a crash or memory growing without end.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/meshes";

class MeshCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = swarmsim::testing::FreshTempDir(
        "swarmsim_mesh_cli", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs a world whose one obstacle is the mesh `file` (copied beside it),
  // under a 2 GiB address-space limit: a reader that grows without end
  // fails the test instead of the machine (and one that blocks, after 2
  // minutes: a guard, not a timing).
  // `env` is prefixed to the command (VARIABLE=value ...).
  swarmsim::testing::CommandResult Run(const fs::path& file, const std::string& env = "") {
    if (file.parent_path() != dir_)
      fs::copy_file(file, dir_ / file.filename(), fs::copy_options::overwrite_existing);
    std::ofstream(dir_ / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                          "obstacles:\n"
                                          "  - {name: part, shape: mesh, file: "
                                       << file.filename().string() << "}\n";
    fs::remove_all(dir_ / "out");
    return swarmsim::testing::RunCommand(
        "cd " + dir_.string() + " && " + swarmsim::testing::AddressSpaceLimit(2097152) + env +
        " timeout 120 " + SWARMSIM_BINARY + " run world.yaml --steps 1 --quiet --out out");
  }
  // The run failed as bad input does: exit 2, `message` on stderr and in
  // out/summary.json (status error).
  void ExpectRefused(const swarmsim::testing::CommandResult& r, const std::string& message) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("error: world.yaml:3:"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    std::ifstream summary_file(dir_ / "out/summary.json");
    ASSERT_TRUE(summary_file.good()) << "no summary.json: " << r.output;
    const auto summary = nlohmann::json::parse(summary_file);
    EXPECT_EQ(summary["status"], "error");
    EXPECT_NE(summary["error"].get<std::string>().find(message), std::string::npos)
        << summary.dump();
  }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  std::string Cube() { return swarmsim::testing::ReadFile(kMeshes / "cube.dae"); }

  fs::path dir_;
};

TEST_F(MeshCliTest, GoodColladaRuns) {
  const auto r = Run(kMeshes / "cube.dae");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream summary_file(dir_ / "out/summary.json");
  ASSERT_TRUE(summary_file.good());
  EXPECT_EQ(nlohmann::json::parse(summary_file)["status"], "ok");
}

TEST_F(MeshCliTest, AMissingAssimpModuleIsRefusedNamingWhereItWasLookedFor) {
  // assimp is a module opened on the first mesh file (swarm/loader/assimp_module.h).
  const std::string nowhere = (dir_ / "nowhere" / "libswarmsim_assimp.so").string();
  const auto r = Run(kMeshes / "cube.dae", "SWARMSIM_ASSIMP_MODULE=" + nowhere);
  ExpectRefused(r, "mesh files need swarmsim's assimp module");
  EXPECT_NE(r.output.find(nowhere + ": cannot open shared object file"), std::string::npos)
      << r.output;
}

TEST_F(MeshCliTest, TrianglesWithTwoPLinesIsRefusedNotAborted) {
  // assimp asserts that the <p> lines made `count` triangles: exit 134 before.
  ExpectRefused(Run(kMeshes / "bad/collada_two_p.dae"),
                "collada_two_p.dae:29: <triangles> count=\"12\" needs exactly one <p>, not 2");
}

TEST_F(MeshCliTest, NonIntegerIndicesAreRefusedBeforeMemoryRunsAway) {
  ExpectRefused(Run(kMeshes / "bad/collada_nan_index.dae"),
                "collada_nan_index.dae:31: <p> index '.NaN' is not a non-negative integer");
  // The other tokens, each in the cube's first <p>.
  const std::string cube = Cube();
  const size_t at = cube.find("<p>0 2 1");
  ASSERT_NE(at, std::string::npos);
  for (const std::string token : {"inf", "1e-320", "0x7fffffff", "-1", "2.5"}) {
    std::string text = cube;
    text.replace(at + 5, 1, token);
    Write("token.dae", text);
    ExpectRefused(Run(dir_ / "token.dae"),
                  "token.dae:31: <p> index '" + token + "' is not a non-negative integer");
  }
}

TEST_F(MeshCliTest, NodeThatInstancesItselfIsRefusedNotACrash) {
  // assimp recursed until the stack overflowed (exit 139).
  ExpectRefused(Run(kMeshes / "bad/collada_instance_cycle.dae"),
                "collada_instance_cycle.dae:38: node 'cube' contains itself");
}

TEST_F(MeshCliTest, StlAndObjHeadersAndIndicesAreChecked) {
  ExpectRefused(Run(kMeshes / "bad/stl_count_wraps.stl"),
                "stl_count_wraps.stl: binary STL header says 2,147,483,648 triangles, which need "
                "107,374,182,484 bytes, but the file has 84");
  ExpectRefused(Run(kMeshes / "bad/obj_bad_index.obj"),
                "obj_bad_index.obj:5: face index 'x' is not a nonzero integer");
  // 2,100 OBJ polygons of 1,000 corners (998 triangles each, at the corner
  // limit): more triangles than a mesh may have, past the 2,005th face.
  std::string face = "f";
  for (int k = 0; k < 1000; ++k) {
    face += ' ';
    face += static_cast<char>('1' + k % 3);
  }
  face += '\n';
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int k = 0; k < 2100; ++k) obj += face;
  Write("huge.obj", obj);
  ExpectRefused(Run(dir_ / "huge.obj"),
                "huge.obj:2008: the faces up to here make more than 2,000,000 triangles");
}

TEST_F(MeshCliTest, MaterialLibraryThatIsAFifoDoesNotBlock) {
  // assimp opened it and waited for a writer forever.
  Write("part.obj", "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  ASSERT_EQ(swarmsim::testing::RunCommand("mkfifo " + (dir_ / "fifo.mtl").string()).exit_code, 0);
  const auto r = Run(dir_ / "part.obj");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

}  // namespace
