#include "capture/gl_context.hpp"

#include <epoxy/gl.h>

#include <cstring>

namespace pbflow::gl {

namespace {

bool has_word(const char* list, const char* word) {
  if (!list) return false;
  size_t n = std::strlen(word);
  for (const char* p = std::strstr(list, word); p; p = std::strstr(p + 1, word))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

void GLAPIENTRY on_debug_message(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                                 const void* user) {
  // Errors and undefined behaviour fail the tests; performance hints do not.
  if (type == GL_DEBUG_TYPE_ERROR || type == GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR || severity == GL_DEBUG_SEVERITY_HIGH)
    static_cast<std::vector<std::string>*>(const_cast<void*>(user))->push_back(message);
}

}  // namespace

Context::Context(const Options& options) : debug_(options.debug) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_word(client, "EGL_EXT_platform_base"))
    throw Error("EGL lacks EGL_EXT_platform_base: no off-screen OpenGL (install libegl1 and libegl-mesa0)");

  // Hardware devices first (a real GPU), then Mesa's surfaceless platform, then any
  // software device the device platform lists.
  std::vector<std::pair<EGLDisplay, std::string>> candidates, software;
  if (has_word(client, "EGL_EXT_platform_device") && has_word(client, "EGL_EXT_device_enumeration")) {
    EGLint count = 0;
    eglQueryDevicesEXT(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(size_t(std::max(count, 0)));
    if (count > 0) eglQueryDevicesEXT(count, devices.data(), &count);
    for (EGLDeviceEXT dev : devices) {
      EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, dev, nullptr);
      if (d == EGL_NO_DISPLAY) continue;
      bool is_software = has_word(eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS), "EGL_MESA_device_software");
      (is_software ? software : candidates).emplace_back(d, "EGL device platform");
    }
  }
  if (has_word(client, "EGL_MESA_platform_surfaceless"))
    candidates.emplace_back(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                            "EGL surfaceless platform");
  candidates.insert(candidates.end(), software.begin(), software.end());
  // The solver's device where asked: a display that says another UUID is let go; the first
  // that cannot say is kept in reserve, taken where none says the solver's.
  std::string others;
  std::optional<std::pair<EGLDisplay, std::string>> unknown;
  for (auto& [display, platform] : candidates) {
    if (display == EGL_NO_DISPLAY || !try_display(display, platform)) continue;
    const std::optional<Uuid> uuid = options.device_uuid ? device_uuid() : std::nullopt;
    if (!options.device_uuid || uuid == options.device_uuid) break;
    if (uuid) others += (others.empty() ? "" : "; ") + description_ + renderer_name();
    else if (!unknown) unknown.emplace(display, platform);
    release();
  }
  if (context_ == EGL_NO_CONTEXT && unknown) try_display(unknown->first, unknown->second);
  if (context_ == EGL_NO_CONTEXT && !others.empty())
    throw Error("no EGL device is the Vulkan device the solver runs on (EGL offers " + others +
                "): pick a device both can use with --device (pbflow devices)");
  if (context_ == EGL_NO_CONTEXT)
    throw Error("no EGL display offers an OpenGL 4.5 core context (" + std::to_string(candidates.size()) +
                " tried; install libegl-mesa0 and libgl1-mesa-dri, or a GPU driver with EGL)");

  if (debug_) {
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(on_debug_message, &messages_);
  }
  description_ += renderer_name() + ", OpenGL " + reinterpret_cast<const char*>(glGetString(GL_VERSION));
}

bool Context::try_display(EGLDisplay display, const std::string& platform) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return false;
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  bool no_config = has_word(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_no_config_context");
  if (!no_config && (!eglChooseConfig(display, config_attribs, &config, 1, &configs) || configs == 0)) {
    eglTerminate(display);
    return false;
  }
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                                    EGL_CONTEXT_MINOR_VERSION, 5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_CONTEXT_OPENGL_DEBUG, debug_ ? EGL_TRUE : EGL_FALSE,
                                    EGL_NONE};
  if (!eglBindAPI(EGL_OPENGL_API)) {
    eglTerminate(display);
    return false;
  }
  EGLContext context = eglCreateContext(display, no_config ? EGL_NO_CONFIG_KHR : config, EGL_NO_CONTEXT,
                                        context_attribs);
  if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
    eglTerminate(display);
    return false;
  }
  display_ = display;
  context_ = context;
  description_ = platform;
  return true;
}

Context::~Context() { release(); }

void Context::release() noexcept {
  if (display_ == EGL_NO_DISPLAY) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
  eglTerminate(display_);
  display_ = EGL_NO_DISPLAY;
  context_ = EGL_NO_CONTEXT;
}

bool Context::has_extension(const char* name) const { return epoxy_has_gl_extension(name); }

std::string Context::renderer_name() const {
  return std::string(", ") + reinterpret_cast<const char*>(glGetString(GL_RENDERER));
}

std::optional<Context::Uuid> Context::device_uuid() const {
  if (!has_extension("GL_EXT_memory_object")) return std::nullopt;
  Uuid uuid{};
  glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, 0, uuid.data());
  return uuid;
}

std::vector<std::string> Context::errors() const {
  std::vector<std::string> all = messages_;
  for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) all.push_back("glGetError " + std::to_string(e));
  return all;
}

}  // namespace pbflow::gl
