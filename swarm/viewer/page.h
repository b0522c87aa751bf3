// The page as the server sends it and as --export writes it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace swarmsim::viewer {

// The recording of an output folder.
inline constexpr std::string_view kRecordingFile = "recording.swrec";

// What `swarmsim view` tells the page (its URL's parameters override it).
struct PageOptions {
  int64_t mesh_budget = -1;  // triangles of meshes drawn in full (--mesh-budget); -1: the page's
};

// index.html loading viewer.js, which reads recording.swrec from the server.
std::string ServedPage(const PageOptions& options = {});
// One self-contained page: the script inline and `recording` (the file's
// bytes) base64-encoded inside, playable from disk (file://).
std::string ExportedPage(std::string_view recording, const PageOptions& options = {});

// Writes ExportedPage of the first `size` bytes of `folder`'s recording (its
// whole chunks) to `html_file`; throws Error when the recording cannot be
// read or the file written.
void ExportFolder(const std::filesystem::path& folder, uint64_t size,
                  const std::filesystem::path& html_file, const PageOptions& options = {});

}  // namespace swarmsim::viewer
