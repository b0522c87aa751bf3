#include "framework/display_path.h"

namespace swarmsim {

namespace fs = std::filesystem;

std::string DisplayPath(const fs::path& path) {
  if (path.is_relative()) return path.lexically_normal().generic_string();
  std::error_code ec;
  const fs::path cwd = fs::current_path(ec);
  if (!ec) {
    const fs::path rel = path.lexically_normal().lexically_relative(cwd);
    if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
  }
  return path.lexically_normal().generic_string();
}

}  // namespace swarmsim
