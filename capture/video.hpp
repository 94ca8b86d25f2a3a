#pragma once
// An H.264 video fed frame by frame to an ffmpeg process through a pipe; the file
// appears under its name only when the encoder finished.
#include <cstdio>
#include <filesystem>
#include <string>

#include "renderer.hpp"

namespace pbflow::capture {

// Where ffmpeg is on PATH, or empty.
std::filesystem::path find_ffmpeg();

class VideoEncoder {
 public:
  // Throws InputError when ffmpeg is missing.
  VideoEncoder(const std::filesystem::path& file, int width, int height, double fps);
  ~VideoEncoder();  // an unfinished video is abandoned: its temporary file is removed
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  void add(const Image& frame);
  void finish();  // waits for ffmpeg, renames the video; throws if ffmpeg failed

 private:
  std::filesystem::path file_, tmp_;
  int width_, height_;
  std::FILE* pipe_ = nullptr;
};

}  // namespace pbflow::capture
