// The published robot descriptions of /work/shared (not in the repository):
// ../shared/urdf (three robots) and ../shared/urdf-corpus (fifteen URDF
// files), for the tests that read them. $SWARMSIM_URDF_DIR /
// $SWARMSIM_URDF_CORPUS first, then beside the source tree (the layout of
// /work/main and its worktrees), then /work/shared. A test that needs them
// and finds none skips with a message (a checkout elsewhere, e.g. in CI).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace swarmsim::testing {

// The folder `name` of ../shared holding `marker`, or "".
inline std::string SharedFolder(const char* env, const std::string& name,
                                const std::string& marker) {
  namespace fs = std::filesystem;
  std::vector<fs::path> folders;
  if (const char* dir = std::getenv(env)) folders.emplace_back(dir);
  folders.push_back(fs::path(SWARMSIM_SOURCE_DIR) / ".." / "shared" / name);
  folders.emplace_back(fs::path("/work/shared") / name);
  for (const fs::path& f : folders) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(f, ec);
    if (!ec && fs::is_regular_file(p / marker, ec)) return p.string();
  }
  return "";
}

inline std::string SharedUrdf() { return SharedFolder("SWARMSIM_URDF_DIR", "urdf", "README.md"); }
inline std::string SharedUrdfCorpus() {
  return SharedFolder("SWARMSIM_URDF_CORPUS", "urdf-corpus", "MANIFEST.tsv");
}

}  // namespace swarmsim::testing

// Skips the test when ../shared/urdf is nowhere to be found; else declares
// `dir` as its absolute path.
#define NEED_SHARED_URDF(dir)                                                  \
  const std::string dir = ::swarmsim::testing::SharedUrdf();                   \
  if (dir.empty())                                                             \
  GTEST_SKIP() << "the shared URDF robots (../shared/urdf) are not here; set " \
                  "SWARMSIM_URDF_DIR to the folder holding fanuc_m10ia, panda, turtlebot3_waffle"

// The same for ../shared/urdf-corpus.
#define NEED_CORPUS(dir)                                                                    \
  const std::string dir = ::swarmsim::testing::SharedUrdfCorpus();                          \
  if (dir.empty())                                                                          \
  GTEST_SKIP() << "the URDF corpus (../shared/urdf-corpus) is not here; set "               \
                  "SWARMSIM_URDF_CORPUS to the folder holding bolt, hyq, icub, tiago, ... " \
                  "and MANIFEST.tsv"
