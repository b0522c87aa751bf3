// PNG files through libpng (8-bit RGB), for the paint layer's output and tests.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace swarmsim::paint {

// Writes `rgb` (width x height x 3 bytes, rows from the top) to `path`.
// Throws swarmsim::Error naming the file on failure.
void WritePng(const std::filesystem::path& path, int width, int height,
              const std::vector<uint8_t>& rgb);

// Reads an image as 8-bit RGB. Throws swarmsim::Error on failure, and for
// an image of more than `max_pixels` pixels (checked from its header, before
// decoding it).
struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // (height x width x 3), rows from the top
};
RgbImage ReadPng(const std::filesystem::path& path, int64_t max_pixels = INT64_MAX);

}  // namespace swarmsim::paint
