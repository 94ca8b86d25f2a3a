#pragma once
// How a frame's particles reach GL: Vulkan memory imported into GL (zero-copy: the
// solver copies its buffers on the device into memory GL reads), or a read-back
// through the host (any solver, any driver pair).
#include <memory>

#include "capture/gl_context.hpp"
#include "capture/gl_objects.hpp"
#include "sim/solver.hpp"

namespace pbflow {
namespace vk {
class Context;
}

namespace capture {

class ParticleTransfer {
 public:
  virtual ~ParticleTransfer() = default;
  // Brings the solver's latest frame into a GL buffer (frame layout) and returns it.
  virtual GLuint update(const Solver& solver) = 0;
  virtual const char* name() const = 0;
};

// Writes a host frame into `buffer` (frame layout, room for f.x.size() particles and
// white_capacity white water particles, of which f's first are written).
void upload_frame(GLuint buffer, const ParticleFrame& f, size_t white_capacity = 0);

// Zero-copy when `allow_shared`, the solver runs on `vk` and both drivers can share
// memory on the same device (matching UUIDs); read-back otherwise.
std::unique_ptr<ParticleTransfer> make_particle_transfer(const Solver& solver, const vk::Context* vk,
                                                         const gl::Context& gl, bool allow_shared);

}  // namespace capture
}  // namespace pbflow
