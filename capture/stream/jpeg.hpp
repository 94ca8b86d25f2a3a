#pragma once
// Frames as JPEG for the live view (pbflow serve): libjpeg-turbo's compressor, one per thread.
#include <string>

#include "capture/renderer.hpp"

namespace pbflow::capture {

class JpegEncoder {
 public:
  static constexpr int kMaxSide = 65500;  // JPEG's largest width or height, in pixels

  explicit JpegEncoder(int quality = 80);
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  std::string encode(const Image& image);  // the JPEG file's bytes; throws std::runtime_error

 private:
  void* handle_;
  int quality_;
};

}  // namespace pbflow::capture
