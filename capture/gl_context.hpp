#pragma once
// An off-screen OpenGL 4.5 core context through EGL, with no window system: the EGL
// device platform on a hardware GPU (NVIDIA), else Mesa's surfaceless platform
// (llvmpipe); where the solver runs on a Vulkan device, the one among them that is that
// device. One per process, current on the thread that made it.
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
  using Uuid = std::array<uint8_t, 16>;
  struct Options {
    bool debug = false;  // a debug context whose error messages are recorded (tests fail on any)
    // The Vulkan device the solver runs on: the context is made on the EGL device with this
    // UUID (GL_EXT_memory_object), or, where EGL offers none that says so and one that cannot
    // say, on that one; where every device says another, Error names them. None: the first.
    std::optional<Uuid> device_uuid;
  };
  explicit Context(const Options& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& description() const { return description_; }  // platform and GL renderer
  bool has_extension(const char* name) const;
  // The GL device's UUID (GL_EXT_memory_object), to match it with a Vulkan device.
  std::optional<Uuid> device_uuid() const;
  // GL errors and debug-output errors seen so far.
  std::vector<std::string> errors() const;

 private:
  bool try_display(EGLDisplay display, const std::string& platform);
  std::string renderer_name() const;  // ", " and GL_RENDERER of the current context
  void release() noexcept;

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string description_;
  bool debug_ = false;
  std::vector<std::string> messages_;
};

}  // namespace pbflow::gl
