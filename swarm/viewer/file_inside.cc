// FileInside (server.h): in the viewer library and in the HTTP module
// (http_server.cc), which serves files through it.
#include <algorithm>
#include <system_error>

#include "swarm/viewer/server.h"

namespace swarmsim::viewer {
namespace fs = std::filesystem;

std::optional<fs::path> FileInside(const fs::path& folder, std::string_view request_path) {
  // A relative path of plain names: no `..`, `.`, empty part, NUL or leading '/'.
  if (request_path.empty() || request_path.front() == '/') return std::nullopt;
  if (request_path.find('\0') != std::string_view::npos) return std::nullopt;
  const fs::path relative(request_path);
  if (relative.is_absolute() || relative.has_root_name()) return std::nullopt;
  for (const fs::path& part : relative)
    if (part.empty() || part == ".." || part == ".") return std::nullopt;
  // Resolved through every symbolic link, it must still be inside the folder.
  std::error_code error;
  const fs::path root = fs::canonical(folder, error);
  if (error) return std::nullopt;
  const fs::path file = fs::canonical(root / relative, error);
  if (error) return std::nullopt;
  const auto [root_end, file_it] =
      std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  if (root_end != root.end() || file_it == file.end()) return std::nullopt;
  if (!fs::is_regular_file(file, error)) return std::nullopt;
  return file;
}

}  // namespace swarmsim::viewer
