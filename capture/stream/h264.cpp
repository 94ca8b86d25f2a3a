#include "capture/stream/h264.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <stdexcept>
#include <utility>

namespace pbflow::capture {

namespace {
std::runtime_error av_failure(const char* what, int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = "";
  av_strerror(code, text, sizeof text);
  return std::runtime_error(std::string("H.264: ") + what + ": " + text);
}
}  // namespace

H264Encoder::H264Encoder(int width, int height, int fps, double bits_per_second) {
  if (width % 2 || height % 2) throw std::runtime_error("H.264 needs an even width and height");
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  if (!codec) throw std::runtime_error("H.264: this libavcodec has no libx264 encoder");
  ctx_ = avcodec_alloc_context3(codec);
  frame_ = av_frame_alloc();
  packet_ = av_packet_alloc();
  if (!ctx_ || !frame_ || !packet_) {
    release();
    throw std::runtime_error("H.264: out of memory");
  }
  ctx_->width = width;
  ctx_->height = height;
  ctx_->time_base = {1, fps};
  ctx_->framerate = {fps, 1};
  ctx_->pix_fmt = AV_PIX_FMT_YUV420P;
  ctx_->gop_size = 2 * fps;  // a keyframe at least every 2 s, besides those asked for
  ctx_->max_b_frames = 0;
  ctx_->bit_rate = int64_t(bits_per_second);
  ctx_->rc_max_rate = int64_t(1.25 * bits_per_second);
  ctx_->rc_buffer_size = int(bits_per_second);  // a second's worth: the rate holds over a second
  av_opt_set(ctx_->priv_data, "preset", "ultrafast", 0);
  av_opt_set(ctx_->priv_data, "tune", "zerolatency", 0);
  av_opt_set(ctx_->priv_data, "profile", "baseline", 0);
  av_opt_set(ctx_->priv_data, "level", "4.0", 0);
  if (const int e = avcodec_open2(ctx_, codec, nullptr); e < 0) {
    release();
    throw av_failure("cannot open libx264", e);
  }
  frame_->format = AV_PIX_FMT_YUV420P;
  frame_->width = width;
  frame_->height = height;
  if (const int e = av_frame_get_buffer(frame_, 0); e < 0) {
    release();
    throw av_failure("cannot allocate a frame", e);
  }
  scale_ = sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height, AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr,
                          nullptr, nullptr);
  if (!scale_) {
    release();
    throw std::runtime_error("H.264: cannot convert RGB to YUV 4:2:0");
  }
}

H264Encoder::~H264Encoder() { release(); }

void H264Encoder::release() {
  sws_freeContext(std::exchange(scale_, nullptr));
  av_packet_free(&packet_);
  av_frame_free(&frame_);
  avcodec_free_context(&ctx_);
}

H264Encoder::Unit H264Encoder::encode(const Image& image, bool keyframe) {
  if (image.width != ctx_->width || image.height != ctx_->height) throw std::runtime_error("H.264: a frame of another size");
  if (const int e = av_frame_make_writable(frame_); e < 0) throw av_failure("frame not writable", e);
  const uint8_t* rgb[1] = {image.rgb.data()};
  const int stride[1] = {3 * image.width};
  sws_scale(scale_, rgb, stride, 0, image.height, frame_->data, frame_->linesize);
  frame_->pts = next_pts_++;
  frame_->pict_type = keyframe ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  if (const int e = avcodec_send_frame(ctx_, frame_); e < 0) throw av_failure("cannot encode", e);
  Unit unit;
  for (;;) {  // zerolatency: this frame's access unit now
    const int e = avcodec_receive_packet(ctx_, packet_);
    if (e == AVERROR(EAGAIN) || e == AVERROR_EOF) break;
    if (e < 0) throw av_failure("cannot encode", e);
    unit.bytes.append(reinterpret_cast<const char*>(packet_->data), size_t(packet_->size));
    unit.keyframe = unit.keyframe || (packet_->flags & AV_PKT_FLAG_KEY);
    av_packet_unref(packet_);
  }
  return unit;
}

}  // namespace pbflow::capture
