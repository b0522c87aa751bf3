// The program's version (swarm/run/version.cc): the project's version in
// CMakeLists.txt, as `swarmsim version` prints it and summaries record it.
#include "swarm/run/version.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

// The VERSION of CMakeLists.txt's project() line.
std::string ProjectVersion() {
  const std::string cmake = testing::ReadFile(std::string(SWARMSIM_SOURCE_DIR) + "/CMakeLists.txt");
  const std::string key = "project(swarmsim VERSION ";
  const size_t at = cmake.find(key);
  if (at == std::string::npos) return "";
  const size_t begin = at + key.size();
  const size_t end = cmake.find_first_not_of("0123456789.", begin);
  return cmake.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

TEST(VersionTest, IsTheProjectsVersion) {
  const std::string project = ProjectVersion();
  ASSERT_FALSE(project.empty()) << "no project(swarmsim VERSION ...) in CMakeLists.txt";
  EXPECT_EQ(std::string(Version()), project);
}

TEST(VersionTest, TheProgramPrintsIt) {
  const auto r = testing::RunProgram("version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "swarmsim " + std::string(Version()) + "\n");
}

}  // namespace
}  // namespace swarmsim
