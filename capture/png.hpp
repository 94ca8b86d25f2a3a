#pragma once
// PNG frames through libpng's simplified API, written atomically.
#include <filesystem>

#include "capture/renderer.hpp"

namespace pbflow::capture {

void write_png(const std::filesystem::path& path, const Image& image);
Image read_png(const std::filesystem::path& path);  // RGB8; throws std::runtime_error

}  // namespace pbflow::capture
