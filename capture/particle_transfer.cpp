#include "capture/particle_transfer.hpp"

#include <algorithm>

#include "gpu/gpu_solver.hpp"
#include "vk/buffer.hpp"
#include "vk/context.hpp"

namespace pbflow::capture {

void upload_frame(GLuint buffer, const ParticleFrame& f, size_t white_capacity) {
  const FrameOffsets to = frame_offsets(f.x.size(), white_capacity);
  auto put = [&](size_t offset, size_t next, const void* data) {
    glNamedBufferSubData(buffer, GLintptr(offset), GLsizeiptr(next - offset), data);
  };
  put(to.x, to.v, f.x.data());
  put(to.v, to.rho, f.v.data());
  put(to.rho, to.x_smooth, f.rho.data());
  // Without smoothed positions, x stands in (as GpuSolver::copy_frame), and zeros draw spheres.
  put(to.x_smooth, to.shape, (f.x_smooth.empty() ? f.x : f.x_smooth).data());
  const std::vector<glm::vec4> spheres(f.shape.empty() ? 2 * f.x.size() : 0, glm::vec4(0.0f));
  put(to.shape, to.white_count, (f.shape.empty() ? spheres : f.shape).data());
  const size_t white = std::min(f.white_x.size(), white_capacity);
  put(to.white_count, to.white_x, white_header(white).data());
  if (white) {
    put(to.white_x, to.white_x + white * sizeof(glm::vec4), f.white_x.data());
    put(to.white_v, to.white_v + white * sizeof(glm::vec4), f.white_v.data());
  }
}

namespace {

class ReadBack : public ParticleTransfer {
 public:
  ReadBack(size_t n, size_t white) : white_(white), buffer_(gl::make_buffer(GLsizeiptr(frame_bytes(n, white)))) {}
  GLuint update(const Solver& solver) override {
    upload_frame(buffer_, solver.read_frame(), white_);
    return buffer_;
  }
  const char* name() const override { return "read-back through the host"; }

 private:
  size_t white_;
  gl::Object buffer_;
};

class Shared : public ParticleTransfer {
 public:
  // The 64 KiB of slack: llvmpipe (Mesa 22.3) refuses a buffer that fills its imported
  // memory object exactly (GL_OUT_OF_MEMORY), as it rounds the buffer's size up.
  Shared(const GpuSolver& solver, const vk::Context& vk)
      : vk_buffer_(vk, frame_bytes(solver.capacity(), solver.white_water_capacity()) + 65536, vk::Memory::Shared) {
    GLuint memory = 0;
    glCreateMemoryObjectsEXT(1, &memory);
    memory_ = gl::Object(memory, [](GLuint m) { glDeleteMemoryObjectsEXT(1, &m); });
    // GL owns the fd from here on.
    glImportMemoryFdEXT(memory_, vk_buffer_.allocation_bytes(), GL_HANDLE_TYPE_OPAQUE_FD_EXT, vk_buffer_.export_fd());
    GLuint buffer = 0;
    glCreateBuffers(1, &buffer);
    buffer_ = gl::Object(buffer, [](GLuint b) { glDeleteBuffers(1, &b); });
    glNamedBufferStorageMemEXT(buffer_, GLsizeiptr(frame_bytes(solver.capacity(), solver.white_water_capacity())), memory_, 0);
    if (GLenum e = glGetError(); e != GL_NO_ERROR)
      throw gl::Error("GL could not import the solver's Vulkan memory (GL error " + std::to_string(e) + ")");
  }
  GLuint update(const Solver& solver) override {
    // copy_frame waits for the device, so GL reads a finished frame.
    static_cast<const GpuSolver&>(solver).copy_frame(vk_buffer_);
    return buffer_;
  }
  const char* name() const override { return "zero-copy (Vulkan memory imported into GL)"; }

 private:
  vk::Buffer vk_buffer_;
  gl::Object memory_, buffer_;  // the buffer goes before the memory it lies in
};

}  // namespace

std::unique_ptr<ParticleTransfer> make_particle_transfer(const Solver& solver, const vk::Context* vk,
                                                         const gl::Context& gl, bool allow_shared) {
  auto gpu = dynamic_cast<const GpuSolver*>(&solver);
  auto uuid = gl.device_uuid();
  bool shareable = allow_shared && gpu && vk && vk->external_memory_fd() &&
                   gl.has_extension("GL_EXT_memory_object_fd") && uuid &&
                   std::equal(uuid->begin(), uuid->end(), vk->device_uuid().begin());
  if (shareable) return std::make_unique<Shared>(*gpu, *vk);
  return std::make_unique<ReadBack>(solver.capacity(), solver.white_water_capacity());
}

}  // namespace pbflow::capture
