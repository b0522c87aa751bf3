// The libav module (modules/rendering/video/libav_loader.cc): FFmpeg is
// mapped by a run that writes a video (tests/framework/shared_library_test.cc:
// and by no other), the module is found beside the build, and a module that cannot be loaded is an
// error naming every path tried and why, in-process and from the program (a message and exit code
// 2, never a crash).
#include "modules/rendering/video/libav_loader.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/shared_library.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::video {
namespace {

using testing::ErrorOf;
using testing::FreshTempDir;
using testing::RunCommand;
using testing::RunProgram;

TEST(LibavLoaderTest, AModuleThatCannotBeOpenedIsAnErrorNamingEachPathTriedAndWhy) {
  const std::string error = ErrorOf([] {
    LoadLibavModule({"/nonexistent/libswarmsim_libav.so", "/nonexistent/lib/other.so"});
  });
  EXPECT_CONTAINS(error, "libav module");
  EXPECT_CONTAINS(error, "/nonexistent/libswarmsim_libav.so: ");
  EXPECT_CONTAINS(error, "/nonexistent/lib/other.so: ");
  EXPECT_CONTAINS(error, "cannot open shared object file");  // dlerror()'s reason
  EXPECT_CONTAINS(error, kLibavModuleVariable);
}

TEST(LibavLoaderTest, ALibraryThatIsNotTheModuleIsRefused) {
  const std::string error = ErrorOf([] { LoadLibavModule({"libm.so.6"}); });
  EXPECT_CONTAINS(error,
                  "libm.so.6: not libswarmsim_libav.so: it does not export swarmsim_libav_module");
}

TEST(LibavLoaderTest, TheVariableIsTheOnlyPlaceLookedAtWhenSet) {
  ASSERT_EQ(setenv(kLibavModuleVariable, "/somewhere/libav.so", 1), 0);
  EXPECT_EQ(LibavModuleCandidates(), std::vector<std::filesystem::path>{"/somewhere/libav.so"});
  ASSERT_EQ(unsetenv(kLibavModuleVariable), 0);
  const std::vector<std::filesystem::path> candidates = LibavModuleCandidates();
  EXPECT_TRUE(std::any_of(candidates.begin(), candidates.end(), [](const std::filesystem::path& p) {
    return exists(p);
  })) << "the build's module is among the places looked at";
}

TEST(LibavLoaderTest, TheBuildsModuleLoads) {
  EXPECT_EQ(Libav().version, kLibavModuleVersion);
  EXPECT_NE(Libav().open_encoder, nullptr);
  EXPECT_NE(Libav().open_decoder, nullptr);
}

TEST(LibavLoaderTest, AModuleOfAnotherVersionIsRefused) {
  OwnLibrary library{"libswarmsim_libav.so",  "",
                     kLibavModuleVariable,    kLibavModuleEntry,
                     kLibavModuleVersion + 1, "videos need it"};
  const std::string error = ErrorOf([&] { LoadOwnLibrary(library, LibavModuleCandidates()); });
  EXPECT_CONTAINS(error, "libswarmsim_libav.so: from another swarmsim build (version " +
                             std::to_string(kLibavModuleVersion) + ", this one needs " +
                             std::to_string(kLibavModuleVersion + 1) + ")");
}

// A world of one box whose script copies /proc/self/maps to maps.txt beside
// the world each step (--trust-scripts), and the folder it is in.
std::filesystem::path MapsWorld(const std::string& name) {
  const std::filesystem::path dir = FreshTempDir("libav_loader", name);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: 0.1}\n"
         "objects:\n"
         "  - {name: box, type: shape, shape: box, size: [0.2, 0.2, 0.2], position: [0, 0, 0.1], "
         "script: maps.lua}\n";
  std::ofstream(dir / "maps.lua") << "function sysCall_actuation()\n"
                                     "  local f = io.open('/proc/self/maps')\n"
                                     "  local maps = f:read('a')\n"
                                     "  f:close()\n"
                                     "  local out = io.open('"
                                  << (dir / "maps.txt").string()
                                  << "', 'w')\n"
                                     "  out:write(maps)\n"
                                     "  out:close()\n"
                                     "end\n";
  return dir;
}

TEST(LibavLoaderTest, TheProgramMapsFfmpegOnlyWhenARunWritesAVideo) {
  const std::filesystem::path dir = MapsWorld("maps");
  const std::string run = "run " + (dir / "world.yaml").string() +
                          " --steps 2 --trust-scripts --quiet --out " + (dir / "out").string();
  testing::CommandResult r = RunProgram(run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::string maps = testing::ReadFile(dir / "maps.txt");
  ASSERT_NE(maps.find("[stack]"), std::string::npos) << "the script read its process's maps";
  EXPECT_EQ(maps.find("libavcodec"), std::string::npos) << maps;
  EXPECT_EQ(maps.find("libswarmsim_libav"), std::string::npos) << maps;

  r = RunProgram(run + " --video --video-size 64x48");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  maps = testing::ReadFile(dir / "maps.txt");
  EXPECT_NE(maps.find("libswarmsim_libav"), std::string::npos) << maps;
  EXPECT_NE(maps.find("libavcodec"), std::string::npos) << maps;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "video.mp4"));
}

TEST(LibavLoaderTest, AProgramWhoseModuleIsMissingSaysSoAndExitsWithAnError) {
  const std::filesystem::path dir = MapsWorld("missing");
  const std::string env =
      std::string(kLibavModuleVariable) + "=" + (dir / "nowhere" / "libswarmsim_libav.so").string();
  const std::string run = "run " + (dir / "world.yaml").string() +
                          " --steps 2 --trust-scripts --quiet --out " + (dir / "out").string();
  testing::CommandResult r =
      RunCommand(env + " " + SWARMSIM_BINARY + " " + run + " --video --video-size 64x48");
  EXPECT_EQ(r.exit_code, 2) << r.output;  // as for any option the run cannot start with
  EXPECT_CONTAINS(r.output, "error: --video: videos need swarmsim's libav module");
  EXPECT_CONTAINS(r.output, (dir / "nowhere" / "libswarmsim_libav.so").string() + ": ");
  EXPECT_CONTAINS(r.output, "cannot open shared object file");
  // A run without a video never looks for it.
  r = RunCommand(env + " " + SWARMSIM_BINARY + " " + run);
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

}  // namespace
}  // namespace swarmsim::video
