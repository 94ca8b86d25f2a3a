#include "capture/stream/jpeg.hpp"

#include <turbojpeg.h>

#include <stdexcept>

namespace pbflow::capture {

JpegEncoder::JpegEncoder(int quality) : handle_(tjInitCompress()), quality_(quality) {
  if (!handle_) throw std::runtime_error(std::string("cannot start the JPEG encoder: ") + tjGetErrorStr());
}

JpegEncoder::~JpegEncoder() { tjDestroy(handle_); }

std::string JpegEncoder::encode(const Image& image) {
  unsigned char* out = nullptr;
  unsigned long size = 0;
  // 4:2:0 and the fast DCT: a live view's frame is seen for one refresh.
  if (tjCompress2(handle_, image.rgb.data(), image.width, 0, image.height, TJPF_RGB, &out, &size, TJSAMP_420, quality_,
                  TJFLAG_FASTDCT) != 0) {
    tjFree(out);
    throw std::runtime_error(std::string("JPEG encoding failed: ") + tjGetErrorStr2(handle_));
  }
  std::string bytes(reinterpret_cast<const char*>(out), size);
  tjFree(out);
  return bytes;
}

}  // namespace pbflow::capture
