#pragma once
// An off-screen OpenGL 4.5 core context through EGL, with no window system: the EGL
// device platform on a hardware GPU (NVIDIA), else Mesa's surfaceless platform
// (llvmpipe). One per process, current on the thread that made it.
#include <epoxy/egl.h>

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pbflow::gl {

// No EGL display or GL 4.5 context could be had, or a GL call failed.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Context {
 public:
  struct Options {
    bool debug = false;  // a debug context whose error messages are recorded (tests fail on any)
  };
  explicit Context(const Options& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& description() const { return description_; }  // platform and GL renderer
  bool has_extension(const char* name) const;
  // The GL device's UUID (GL_EXT_memory_object), to match it with a Vulkan device.
  std::optional<std::array<uint8_t, 16>> device_uuid() const;
  // GL errors and debug-output errors seen so far.
  std::vector<std::string> errors() const;

 private:
  bool try_display(EGLDisplay display, const std::string& platform);
  void release() noexcept;

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string description_;
  bool debug_ = false;
  std::vector<std::string> messages_;
};

}  // namespace pbflow::gl
