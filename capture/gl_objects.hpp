#pragma once
// Move-only owners of GL object names, and shader programs built from the GLSL
// render shaders embedded at build time (shaders/render/).
#include <epoxy/gl.h>

#include <string>
#include <utility>

namespace pbflow::gl {

class Object {
 public:
  using Deleter = void (*)(GLuint);
  Object() = default;
  Object(GLuint id, Deleter deleter) : id_(id), deleter_(deleter) {}
  ~Object() { reset(); }
  Object(Object&& o) noexcept : id_(std::exchange(o.id_, 0)), deleter_(o.deleter_) {}
  Object& operator=(Object&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
      deleter_ = o.deleter_;
    }
    return *this;
  }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;

  GLuint id() const { return id_; }
  operator GLuint() const { return id_; }

 private:
  void reset() {
    if (id_ && deleter_) deleter_(id_);
    id_ = 0;
  }
  GLuint id_ = 0;
  Deleter deleter_ = nullptr;
};

Object make_buffer(GLsizeiptr bytes, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
// 2D, one level, clamped; `filter`: GL_NEAREST, or GL_LINEAR for a texture sampled at another size.
Object make_texture(GLenum format, int width, int height, GLenum filter = GL_NEAREST);
Object make_framebuffer(std::initializer_list<GLuint> colour, GLuint depth);  // throws if incomplete
// The same storage read as another format of its size (an R32UI image read as R32F).
Object make_texture_view(GLuint texture, GLenum format);
Object make_vertex_array();
Object make_timestamp_query();  // GL_TIMESTAMP: the GPU's clock when the commands before it are done

// A program linked from the embedded shaders named `vertex` and `fragment` (file
// stems); throws gl::Error with the compiler's log on failure.
Object make_program(const std::string& vertex, const std::string& fragment);
Object make_compute_program(const std::string& compute);

}  // namespace pbflow::gl
