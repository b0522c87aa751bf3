// Opening libraries at run time (framework/shared_library.h): why a library
// could not be opened, where swarmsim's own lazily opened modules are looked
// for, and that the program maps none of the heavy libraries they hold
// until something uses them (libav for videos, OMPL for planning, assimp
// for mesh files, cpp-httplib and the OpenSSL it is built with for the
// viewer's server).
#include "framework/shared_library.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/framework/error_of.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

OwnLibrary Example() {
  OwnLibrary library;
  library.file_name = "libswarmsim_example.so";
  library.built_at = "/build/lib/libswarmsim_example.so";
  library.variable = "SWARMSIM_SHARED_LIBRARY_TEST_MODULE";
  library.entry = "swarmsim_example_module";
  library.version = 3;
  library.needed_for = "examples need swarmsim's example module";
  return library;
}

TEST(SharedLibraryTest, AFileThatCannotBeOpenedSaysWhy) {
  std::string why;
  EXPECT_EQ(OpenSharedLibrary("/nonexistent/libx.so", &why), nullptr);
  EXPECT_CONTAINS(why, "cannot open shared object file");
  void* libm = OpenSharedLibrary("libm.so.6", &why);
  ASSERT_NE(libm, nullptr) << why;
  EXPECT_NE(FindSymbol(libm, "cos"), nullptr);
  EXPECT_EQ(FindSymbol(libm, "swarmsim_no_such_symbol"), nullptr);
}

// A library that did not load says so on every use, with the first
// attempt's reasons (it is not looked for again); one that loads gives its table.
TEST(SharedLibraryTest, ALazyLibraryKeepsItsFirstOutcome) {
  OwnLibrary missing = Example();
  ASSERT_EQ(setenv(missing.variable.c_str(), "/nonexistent/libswarmsim_example.so", 1), 0);
  const LazyOwnLibrary lazy(missing);
  const std::string first = ErrorOf([&] { lazy.Get(); });
  EXPECT_CONTAINS(first, "examples need swarmsim's example module");
  EXPECT_CONTAINS(first, "/nonexistent/libswarmsim_example.so");
  // Even once the file would be found, the outcome stays (no second search).
  ASSERT_EQ(unsetenv(missing.variable.c_str()), 0);
  EXPECT_EQ(ErrorOf([&] { lazy.Get(); }), first);
}

TEST(SharedLibraryTest, AModuleIsLookedForBesideTheProgramThenWhereTheBuildPutIt) {
  const OwnLibrary library = Example();
  ASSERT_EQ(unsetenv(library.variable.c_str()), 0);
  const std::filesystem::path program = ProgramFolder();
  ASSERT_FALSE(program.empty());
  const std::vector<std::filesystem::path> candidates = CandidatesOf(library);
  // The test program holds this code: its folder is looked at once.
  EXPECT_EQ(candidates,
            (std::vector<std::filesystem::path>{program / "libswarmsim_example.so",
                                                program / "lib" / "libswarmsim_example.so",
                                                "/build/lib/libswarmsim_example.so"}));
  // The variable, when set, is the only place.
  ASSERT_EQ(setenv(library.variable.c_str(), "/elsewhere/x.so", 1), 0);
  EXPECT_EQ(CandidatesOf(library), std::vector<std::filesystem::path>{"/elsewhere/x.so"});
  ASSERT_EQ(unsetenv(library.variable.c_str()), 0);
}

TEST(SharedLibraryTest, AModuleThatCannotBeLoadedIsAnErrorNamingEachPathAndWhy) {
  const OwnLibrary library = Example();
  const std::string error = ErrorOf([&] {
    LoadOwnLibrary(library, {"/nonexistent/libswarmsim_example.so", "libm.so.6"});
  });
  EXPECT_CONTAINS(error, "examples need swarmsim's example module, and it could not be loaded");
  // dlerror()'s reason, without the path twice.
  EXPECT_CONTAINS(error, "\n  /nonexistent/libswarmsim_example.so: cannot open shared object file");
  EXPECT_CONTAINS(error,
                  "\n  libm.so.6: not libswarmsim_example.so: it does not export "
                  "swarmsim_example_module");
  EXPECT_CONTAINS(error, "(SWARMSIM_SHARED_LIBRARY_TEST_MODULE names its file)");
  EXPECT_CONTAINS(ErrorOf([&] { LoadOwnLibrary(library, {}); }), "tried: nothing");
}

// The libraries swarmsim opens only when a run needs them.
constexpr const char* kLazyLibraries[] = {
    "libavcodec",     "libavformat",      "libswscale", "libswarmsim_libav",
    "libompl",        "libswarmsim_ompl", "libassimp",  "libswarmsim_assimp",
    "libcpp-httplib", "libssl",           "libcrypto",  "libswarmsim_http"};

TEST(SharedLibraryTest, TheProgramNeedsNoneOfItsLazyLibrariesToStart) {
  const testing::CommandResult r = testing::RunCommand("ldd " + std::string(SWARMSIM_BINARY));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("libc.so"), std::string::npos) << r.output;
  for (const char* library : kLazyLibraries)
    EXPECT_EQ(r.output.find(library), std::string::npos) << library << " in\n" << r.output;
}

TEST(SharedLibraryTest, ARunThatNeedsNoneOfThemMapsNoneOfThem) {
  // A box whose script copies its process's /proc/self/maps beside the world.
  const std::filesystem::path dir = testing::FreshTempDir("shared_library", "maps");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: box2d, time_step: 0.1}\n"
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
  const testing::CommandResult r =
      testing::RunProgram("run " + (dir / "world.yaml").string() +
                          " --steps 2 --trust-scripts --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string maps = testing::ReadFile(dir / "maps.txt");
  ASSERT_NE(maps.find("[stack]"), std::string::npos) << "the script read its process's maps";
  for (const char* library : kLazyLibraries)
    EXPECT_EQ(maps.find(library), std::string::npos) << library << " in\n" << maps;
}

}  // namespace
}  // namespace swarmsim
