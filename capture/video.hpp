#pragma once
// An H.264 video fed frame by frame to an ffmpeg process through a pipe; the file
// appears under its name only when the encoder finished. ffmpeg runs in a process group
// of its own, so that a Ctrl-C at the terminal reaches pbflow alone, which then encodes
// the frames done.
#include <sys/types.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "capture/renderer.hpp"

namespace pbflow::capture {

// Where ffmpeg is on PATH, or empty.
std::filesystem::path find_ffmpeg();

class VideoEncoder {
 public:
  // Throws InputError when ffmpeg is missing or the video cannot be written where asked.
  VideoEncoder(const std::filesystem::path& file, int width, int height, double fps);
  ~VideoEncoder();  // an unfinished video is abandoned: its temporary file is removed
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  void add(const Image& frame);
  void finish();  // waits for ffmpeg, renames the video; throws if ffmpeg failed

 private:
  std::string cause() const;  // ": No space left on device", ": File too large" or empty
  std::filesystem::path file_, tmp_;
  int width_, height_;
  std::FILE* pipe_ = nullptr;
  pid_t pid_ = -1;
  int wait();  // closes the pipe and waits for ffmpeg: its exit status
};

}  // namespace pbflow::capture
