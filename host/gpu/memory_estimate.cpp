#include "gpu/memory_estimate.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/input_error.hpp"
#include "gpu/buffer_plan.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {

// Host bytes per particle of a GPU run: the initial lattice (dvec3) and the state uploaded once
// (x, v, x_pred); a frame read back is its frame_bytes and the ids.
constexpr double kHostPerParticleGpuRun = 24 + 72;
// The reference solver: x, v, x_pred, curl (dvec3), rho, lambda, its cell lists, two scratch
// dvec3 arrays and the initial lattice; its neighbour lists are as the GPU's (8 bytes an entry,
// a count), bounded by the capacity. Its outputs: a drawn particle (ReferenceSolver::DrawnParticles)
// and a white water particle.
constexpr double kHostPerParticleCpuRun = 96 + 16 + 16 + 48 + 24, kHostPerCellCpuRun = 24;
constexpr double kHostPerDrawnCpuRun = sizeof(glm::dvec3) + sizeof(glm::dmat3) + sizeof(double);
constexpr double kHostPerWhiteCpuRun = sizeof(WhiteParticle);
// Framebuffers and the image read back: colour and depth for the tank and for a frame (16),
// the fluid's surface targets (24 at full size: two RG32F, R32F, depth), RGB copies; the
// surface drawn at full size takes its targets, their smoothing and the driver's copies four
// times over (measured: docs/performance.md, "Measurements behind the code").
constexpr double kBytesPerPixel = 48, kBytesPerPixelFullSurface = 40;
// What a run holds besides its arrays, measured as peak resident memory (tests/memory_test.cpp
// holds the estimate above the measured peak): the process and its libraries (the live view's
// libavcodec, libx264 and Asio among them, and OpenVDB, TBB and assimp for meshes: 54 MiB at
// the reference run's peak, 24 without them); a Vulkan driver in the process, its compiler
// and JIT code included; a GL context for the renderer; each with room over what was measured
// (docs/performance.md, "Measurements behind the code").
constexpr double kMiB = 1 << 20, kProcessBytes = 64 * kMiB, kDriverBytes = 128 * kMiB, kRendererBytes = 128 * kMiB;

double gib(uint64_t bytes) { return double(bytes) / double(1ULL << 30); }

uint64_t meminfo_available() {
  std::ifstream in("/proc/meminfo");
  for (std::string key; in >> key;) {
    uint64_t kib = 0;
    in >> kib;
    if (key == "MemAvailable:") return kib << 10;
    in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return std::numeric_limits<uint64_t>::max();
}

uint64_t read_number(const char* path) {
  std::ifstream in(path);
  uint64_t n = 0;
  return (in >> n) ? n : std::numeric_limits<uint64_t>::max();  // "max" reads as no limit
}

uint64_t address_space_in_use() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmSize:", 0) == 0) return std::stoull(line.substr(7)) << 10;
  return 0;
}

}  // namespace

uint32_t neighbour_capacity_on(const Derived& d, double particles, const vk::DeviceInfo& device) {
  const double list_words_all = double(list_words(d.neighbour_capacity)) * particles;
  const bool past_range =
      device.max_storage_buffer_range && sizeof(uint32_t) * list_words_all > double(device.max_storage_buffer_range);
  const bool past_texels =  // one uvec4 texel per group of four words
      device.max_texel_buffer_elements && list_words_all / 4 > double(device.max_texel_buffer_elements);
  return past_range || past_texels ? 0 : d.neighbour_capacity;
}

MemoryNeed memory_need(const Derived& d, double particles, const vk::DeviceInfo* device, Picture picture,
                       FrameOutputs outputs) {
  const double cells = double(d.grid.x) * d.grid.y * d.grid.z, pixels = picture.pixels;
  const double picture_bytes =
      pixels > 0 ? kRendererBytes + (kBytesPerPixel + (picture.full_surface ? kBytesPerPixelFullSurface : 0)) * pixels : 0;
  // Room for what the emitters bring (Derived::capacity_for); capped where the count is past any
  // machine, so that the conversions stay defined.
  if (d.flows()) particles = std::max(particles, double(d.capacity_for(size_t(std::min(particles, 1e15)))));
  const uint64_t count = uint64_t(std::ceil(std::min(particles, 1e15)));
  const size_t white = d.white_capacity();
  // A frame read back (capture, export), with room for the white water (Solver::white_water_capacity).
  const double frame = double(frame_bytes(count, white)) + sizeof(uint32_t) * particles;
  MemoryNeed need;
  double host = kProcessBytes + picture_bytes + frame;
  if (device) {
    Derived on_device = d;
    on_device.neighbour_capacity = neighbour_capacity_on(d, particles, *device);
    const SolverBuffers plan = plan_buffers(on_device, count, outputs);
    // A drawn frame is copied into a buffer the renderer shares (frame_bytes).
    need.device = plan.total() + (pixels > 0 ? frame_bytes(count, white) : 0);
    need.largest_array = plan.largest();
    // White water's lists where on, and its room in the frames, on or off: each array the cap's vec4s.
    need.white_water = plan.white_water() + (pixels > 0 ? 2 * white * sizeof(glm::vec4) : 0);
    need.largest_white_array = white * sizeof(glm::vec4);
    if (pixels > 0) {  // the drawn frame's buffer is one array too: its larger share names the advice
      uint64_t& largest = frame_bytes(0, white) > frame_bytes(count) ? need.largest_white_array : need.largest_array;
      largest = std::max<uint64_t>(largest, frame_bytes(count, white));
    }
    host += kHostPerParticleGpuRun * particles + kDriverBytes;
  } else {
    const double list_bytes = 8.0 * d.neighbour_capacity + 4;  // ReferenceSolver's lists, as the GPU's
    host += (kHostPerParticleCpuRun + list_bytes + (outputs.surface ? kHostPerDrawnCpuRun : 0)) * particles +
            kHostPerCellCpuRun * cells + (outputs.white_water ? kHostPerWhiteCpuRun * double(white) : 0);
  }
  need.host = uint64_t(host);
  need.picture = uint64_t(picture_bytes);
  return need;
}

uint64_t host_memory_available() {
  uint64_t available = meminfo_available();
  uint64_t limit = read_number("/sys/fs/cgroup/memory.max"), used = read_number("/sys/fs/cgroup/memory.current");
  if (limit != std::numeric_limits<uint64_t>::max() && used != std::numeric_limits<uint64_t>::max())
    available = std::min(available, limit > used ? limit - used : 0);
  rlimit as{};
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    uint64_t in_use = address_space_in_use();
    available = std::min<uint64_t>(available, as.rlim_cur > in_use ? as.rlim_cur - in_use : 0);
  }
  return available;
}

void check_device_memory(const MemoryNeed& need, const vk::DeviceInfo& device, const MemoryAdvice& advice) {
  std::ostringstream m;
  m.precision(3);
  if (device.max_storage_buffer_range && need.largest_array > device.max_storage_buffer_range) {
    m << "the run needs arrays of " << gib(need.largest_array) << " GiB, " << device.name << " takes at most "
      << gib(device.max_storage_buffer_range) << " GiB in one: " << advice.particles;
    throw InputError(m.str());
  }
  if (device.max_storage_buffer_range && need.largest_white_array > device.max_storage_buffer_range) {
    m << "white water needs arrays of " << gib(need.largest_white_array) << " GiB, " << device.name
      << " takes at most " << gib(device.max_storage_buffer_range) << " GiB in one: " << advice.white_water;
    throw InputError(m.str());
  }
  if (device.device_local_bytes && need.device > device.device_local_bytes) {
    m << "the run needs " << gib(need.device) << " GiB of GPU memory, " << device.name << " has "
      << gib(device.device_local_bytes)
      << " GiB: " << (2 * need.white_water > need.device ? advice.white_water : advice.particles);
    throw InputError(m.str());
  }
}

uint64_t host_bytes(const MemoryNeed& need, const vk::DeviceInfo* device) {
  // A CPU Vulkan device (lavapipe) keeps its buffers in host memory.
  return need.host + (device && device->kind == "cpu" ? need.device : 0);
}

void check_memory(const MemoryNeed& need, const vk::DeviceInfo* device, const MemoryAdvice& advice) {
  if (device) check_device_memory(need, *device, advice);
  const uint64_t host_need = host_bytes(need, device);
  const uint64_t host = host_memory_available();
  if (host_need > host) {
    std::ostringstream m;
    m.precision(3);
    m << "the run needs " << gib(host_need) << " GiB of memory, this machine has " << gib(host)
      << " GiB available: "
      << (2 * need.picture > host_need       ? advice.picture
          : 2 * need.white_water > host_need ? advice.white_water
                                             : advice.particles);
    throw InputError(m.str());
  }
}

}  // namespace pbflow
