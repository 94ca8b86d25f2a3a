#pragma once
// The memory a run needs, estimated before anything is allocated, so that a scene too large
// for the machine is refused at once with the numbers ("needs X GiB, the device has Y")
// instead of failing in an allocation after minutes of set-up.
#include <cstdint>
#include <string>

#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

namespace vk {
struct DeviceInfo;
}

struct MemoryNeed {
  uint64_t device = 0;  // GPU buffers (gpu/buffer_plan.hpp; none for the reference solver)
  uint64_t host = 0;    // the solver's host arrays, host copies of a frame, framebuffers
  uint64_t largest_array = 0;  // one GPU buffer (a vec4 per particle, the drawn frame's), against the storage buffer range
  uint64_t picture = 0;        // of `host`, what the image's size takes (framebuffers, the surface's targets)
  uint64_t white_water = 0;    // of `device`, white water's lists (white_water.max_particles), where on
  uint64_t largest_white_array = 0;  // one of them (the drawn frame's where they are most of it), against the range
};

// The image a run draws: its pixels (0 without rendering), and whether the fluid's surface is
// drawn at full size (--fluid-resolution full) rather than half.
struct Picture {
  double pixels = 0;
  bool full_surface = false;
};

// The neighbour capacity a GPU run gets: the scene's (Derived::neighbour_capacity), or 0
// where one list for `particles` would pass the device's storage buffer range (llvmpipe's
// 128 MiB: ~460k particles at 72 entries) or its texel buffer size (the passes read the
// list as uvec4 texels; NVIDIA's 2^27 texels hold 4M particles at 72 entries). At 0 there
// are no lists: every pass walks its cells (shaders/neighbours.glsl), and the run still fits.
uint32_t neighbour_capacity_on(const Derived& d, double particles, const vk::DeviceInfo& device);

// `particles` as estimated from the scene; `device` null for the reference solver; `outputs`
// what each frame produces (Solver::set_outputs).
MemoryNeed memory_need(const Derived& d, double particles, const vk::DeviceInfo* device, Picture picture = {},
                       FrameOutputs outputs = {});

// Host memory this process may still take: the least of /proc/meminfo's MemAvailable, the
// cgroup's limit and RLIMIT_AS, each less what is in use.
uint64_t host_memory_available();

// What to change where a run does not fit: the option that asked for the memory.
struct MemoryAdvice {
  std::string particles = "raise particle_spacing";  // the particles take most of it
  std::string picture = "lower --width and --height";  // the image does
  std::string white_water = "lower white_water.max_particles, or set white_water.enabled=false";  // white water does
};

// Throws InputError when `need` does not fit the device: its largest array past the
// storage buffer range, or all its buffers past the device's memory.
void check_device_memory(const MemoryNeed& need, const vk::DeviceInfo& device, const MemoryAdvice& advice = {});
// The host memory a run needs: `need.host`, and its GPU buffers on a CPU Vulkan device.
uint64_t host_bytes(const MemoryNeed& need, const vk::DeviceInfo* device);
// As check_device_memory where `device` is not null, and then the host; the message ends with
// the advice for whichever part, particles or picture, needs more.
void check_memory(const MemoryNeed& need, const vk::DeviceInfo* device, const MemoryAdvice& advice = {});

}  // namespace pbflow
