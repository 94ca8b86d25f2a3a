#pragma once
// Frames as H.264 for the live view (pbflow serve): libavcodec's libx264 at the lowest latency
// (no B-frames, zerolatency, one frame in, one access unit out), Annex B with the parameter sets
// repeated at every keyframe, so that a viewer can start at any keyframe. Baseline profile:
// what a browser's WebCodecs decodes everywhere.
#include <string>

#include "capture/renderer.hpp"

struct AVCodecContext;
struct AVFrame;
struct AVPacket;
struct SwsContext;

namespace pbflow::capture {

class H264Encoder {
 public:
  // Needs an even width and height (4:2:0). `bits_per_second`: the rate it aims at.
  H264Encoder(int width, int height, int fps, double bits_per_second);
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  struct Unit {
    std::string bytes;  // one access unit, Annex B
    bool keyframe = false;
  };
  // Encodes the next frame; `keyframe` forces an IDR (a viewer joined or fell behind).
  Unit encode(const Image& image, bool keyframe);
  // The codec string a decoder is configured with (WebCodecs' `codec`).
  static const char* codec_string() { return "avc1.42E028"; }  // baseline, level 4.0

 private:
  void release();
  AVCodecContext* ctx_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  SwsContext* scale_ = nullptr;
  long long next_pts_ = 0;
};

}  // namespace pbflow::capture
