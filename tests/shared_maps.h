// The OctoMap test map of /work/shared/maps (not in the repository): where
// to find it, for the tests that read it. $SWARMSIM_MAPS_DIR first, then
// ../shared/maps beside the source tree (the layout of /work/main and its
// worktrees), then /work/shared/maps. A test that needs the map and finds
// none skips with a message (a checkout elsewhere, e.g. in CI).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace swarmsim::testing {

inline std::string SharedMap(const std::string& name) {
  namespace fs = std::filesystem;
  std::vector<fs::path> folders;
  if (const char* dir = std::getenv("SWARMSIM_MAPS_DIR")) folders.emplace_back(dir);
  folders.push_back(fs::path(SWARMSIM_SOURCE_DIR) / ".." / "shared" / "maps");
  folders.emplace_back("/work/shared/maps");
  for (const fs::path& folder : folders) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(folder / name, ec);
    if (!ec && fs::is_regular_file(p, ec)) return p.string();
  }
  return "";
}

}  // namespace swarmsim::testing

// Skips the test when the shared map `name` is nowhere to be found; else
// declares `path` as its absolute path.
#define SWARMSIM_NEED_SHARED_MAP(path, name)                                            \
  const std::string path = ::swarmsim::testing::SharedMap(name);                        \
  if (path.empty())                                                                     \
  GTEST_SKIP() << "the shared map " << (name) << " is not here (set SWARMSIM_MAPS_DIR " \
               << "to the folder holding it)"
