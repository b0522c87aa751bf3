// Paths in messages, as the user would recognise them.
#pragma once

#include <filesystem>
#include <string>

namespace swarmsim {

// Relative to the current directory when the file is below it, else as
// given; lexically normalised ("worlds/models/footbot.yaml").
std::string DisplayPath(const std::filesystem::path& path);

}  // namespace swarmsim
