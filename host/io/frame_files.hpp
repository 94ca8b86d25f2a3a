#pragma once
// Names of per-frame files: DIR/frame_00000.EXT, five digits or as many as the last
// frame number needs, so that names sort in frame order.
#include <filesystem>
#include <string>

namespace pbflow::capture {

inline std::filesystem::path frame_file(const std::filesystem::path& dir, int frame, int frame_count,
                                        const std::string& extension) {
  std::string number = std::to_string(frame);
  size_t digits = std::max<size_t>(5, std::to_string(std::max(frame_count - 1, 0)).size());
  return dir / ("frame_" + std::string(digits - std::min(digits, number.size()), '0') + number + "." + extension);
}

}  // namespace pbflow::capture
