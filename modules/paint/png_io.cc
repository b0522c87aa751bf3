#include "modules/paint/png_io.h"

#include <png.h>

#include <cstring>
#include <string>

#include "framework/error.h"
#include "framework/output_file.h"

namespace swarmsim::paint {

void WritePng(const std::filesystem::path& path, int width, int height,
              const std::vector<uint8_t>& rgb) {
  SWARMSIM_CHECK(rgb.size() == static_cast<size_t>(width) * height * 3, "paint: image size");
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = PNG_FORMAT_RGB;
  // Encoded in memory, then written whole (WriteFileAtomically): a snapshot
  // cut by a full disk never stays behind as a broken PNG.
  png_alloc_size_t size = 0;
  std::vector<uint8_t> bytes;
  bool encoded = png_image_write_get_memory_size(image, size, 0, rgb.data(), 0, nullptr);
  if (encoded) {
    bytes.resize(size);
    encoded = png_image_write_to_memory(&image, bytes.data(), &size, 0, rgb.data(), 0, nullptr);
  }
  if (!encoded) {
    const std::string why = image.message;
    png_image_free(&image);
    throw Error("cannot write '" + path.string() + "': " + why);
  }
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), size));
}

RgbImage ReadPng(const std::filesystem::path& path, int64_t max_pixels) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    throw Error("cannot read '" + path.string() + "': " + image.message);
  if (int64_t{image.width} * int64_t{image.height} > max_pixels) {
    png_image_free(&image);
    throw Error("'" + path.string() + "' is " + std::to_string(image.width) + " x " +
                std::to_string(image.height) + " pixels, over the limit of " +
                std::to_string(max_pixels) + " pixels");
  }
  image.format = PNG_FORMAT_RGB;
  RgbImage out;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) {
    const std::string why = image.message;
    png_image_free(&image);
    throw Error("cannot read '" + path.string() + "': " + why);
  }
  return out;
}

}  // namespace swarmsim::paint
