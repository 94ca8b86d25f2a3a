#include "capture/gl_objects.hpp"

#include <string_view>
#include <vector>

#include "capture/gl_context.hpp"

namespace pbflow {
const std::vector<std::pair<std::string_view, std::string_view>>& render_shaders_text();
}

namespace pbflow::gl {

Object make_buffer(GLsizeiptr bytes, GLbitfield flags) {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  glNamedBufferStorage(id, std::max<GLsizeiptr>(bytes, 4), nullptr, flags);
  return {id, [](GLuint b) { glDeleteBuffers(1, &b); }};
}

Object make_texture(GLenum format, int width, int height, GLenum filter) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, 1, format, width, height);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GLint(filter));
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GLint(filter));
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return {id, [](GLuint t) { glDeleteTextures(1, &t); }};
}

Object make_framebuffer(std::initializer_list<GLuint> colour, GLuint depth) {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  Object fb(id, [](GLuint f) { glDeleteFramebuffers(1, &f); });
  std::vector<GLenum> draw;
  for (GLuint tex : colour) {
    GLenum attachment = GL_COLOR_ATTACHMENT0 + GLenum(draw.size());
    glNamedFramebufferTexture(id, attachment, tex, 0);
    draw.push_back(attachment);
  }
  glNamedFramebufferDrawBuffers(id, GLsizei(draw.size()), draw.data());
  if (depth) glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, depth, 0);
  GLenum status = glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("framebuffer incomplete (status " + std::to_string(status) + ")");
  return fb;
}

Object make_vertex_array() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return {id, [](GLuint v) { glDeleteVertexArrays(1, &v); }};
}

Object make_texture_view(GLuint texture, GLenum format) {
  GLuint id = 0;
  glGenTextures(1, &id);  // a view needs a name never bound: glCreateTextures binds
  glTextureView(id, GL_TEXTURE_2D, texture, format, 0, 1, 0, 1);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return {id, [](GLuint t) { glDeleteTextures(1, &t); }};
}

Object make_timestamp_query() {
  GLuint id = 0;
  glCreateQueries(GL_TIMESTAMP, 1, &id);
  return {id, [](GLuint q) { glDeleteQueries(1, &q); }};
}

namespace {

std::string_view source(const std::string& name) {
  for (const auto& [stem, text] : render_shaders_text())
    if (stem == name) return text;
  throw Error("no embedded render shader named '" + name + "'");
}

// Throws `failure` with the driver's log when `status` (compile or link) is false; one
// check for shaders and programs, given their two query functions.
void require_status(GLuint object, GLenum status, PFNGLGETSHADERIVPROC get_iv, PFNGLGETSHADERINFOLOGPROC get_log,
                    const std::string& failure) {
  GLint ok = 0;
  get_iv(object, status, &ok);
  if (ok) return;
  char log[4096] = {};
  get_log(object, sizeof log, nullptr, log);
  throw Error(failure + ": " + log);
}

Object compile(GLenum stage, const std::string& name) {
  Object shader(glCreateShader(stage), [](GLuint s) { glDeleteShader(s); });
  // GLSL has no #include: every stage gets the shared declarations after its #version (the
  // frame's shape layout, which the solver's shaders include, then the render passes'), and
  // the compute passes, the fluid surface's, its tiles.
  std::string text = "#version 450 core\n" + std::string(source("shape_layout.glsl")) +
                     std::string(source("render_common.glsl")) +
                     (stage == GL_COMPUTE_SHADER ? std::string(source("surface_tiles.glsl")) : "") + "#line 1\n" +
                     std::string(source(name));
  const GLchar* ptr = text.c_str();
  GLint length = GLint(text.size());
  glShaderSource(shader, 1, &ptr, &length);
  glCompileShader(shader);
  require_status(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog,
                 "render shader " + name + " does not compile");
  return shader;
}

Object link(const std::vector<const Object*>& shaders, const std::string& names) {
  Object program(glCreateProgram(), [](GLuint p) { glDeleteProgram(p); });
  for (const Object* shader : shaders) glAttachShader(program, *shader);
  glLinkProgram(program);
  require_status(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog,
                 "render program " + names + " does not link");
  return program;
}

}  // namespace

Object make_program(const std::string& vertex, const std::string& fragment) {
  Object vs = compile(GL_VERTEX_SHADER, vertex), fs = compile(GL_FRAGMENT_SHADER, fragment);
  return link({&vs, &fs}, vertex + " + " + fragment);
}

Object make_compute_program(const std::string& compute) {
  Object cs = compile(GL_COMPUTE_SHADER, compute);
  return link({&cs}, compute);
}

}  // namespace pbflow::gl
