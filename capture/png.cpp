#include "capture/png.hpp"

#include <png.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "io/atomic_file.hpp"

namespace pbflow::capture {

void write_png(const std::filesystem::path& path, const Image& image) {
  write_atomically(path, [&](std::FILE* f) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = png_uint_32(image.width);
    png.height = png_uint_32(image.height);
    png.format = PNG_FORMAT_RGB;
    png.flags = PNG_IMAGE_FLAG_FAST;  // frame sequences favour speed over the last few percent of size
    // libpng reports a failed fwrite as "Write Error"; the stream's errno names the cause
    // (No space left on device, File too large).
    if (!png_image_write_to_stdio(&png, f, 0, image.rgb.data(), 0, nullptr))
      throw std::runtime_error(std::ferror(f) && errno ? std::strerror(errno) : png.message);
  });
}

Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw std::runtime_error("cannot read " + path.string() + ": " + png.message);
  png.format = PNG_FORMAT_RGB;
  Image image{int(png.width), int(png.height), std::vector<uint8_t>(PNG_IMAGE_SIZE(png))};
  if (!png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr))
    throw std::runtime_error("cannot read " + path.string() + ": " + png.message);
  return image;
}

}  // namespace pbflow::capture
