#pragma once
// The device buffers of a GPU run and their sizes in bytes, from the scene and the frame's
// outputs alone. GpuSolver and GpuGrid allocate from this plan and the memory estimate sums it,
// so that the estimate is what a run holds (tests/memory_test.cpp measures both).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "shaders/contract.h"
#include "sim/params.hpp"
#include "sim/frame_plan.hpp"

namespace pbflow {

// watch.comp's buffer, a field at each of shaders/contract.h's words; as the host resets it
// before a frame.
struct WatchWords {
  uint32_t flags = 0;
  uint32_t first_step = ~0u;  // none yet
  uint32_t counts[3] = {0, 0, 0};  // not finite, too fast, outside
  uint32_t step = 0;
};
static_assert(offsetof(WatchWords, flags) == WATCH_FLAGS * 4 && offsetof(WatchWords, first_step) == WATCH_FIRST_STEP * 4 &&
              offsetof(WatchWords, counts) == WATCH_COUNTS * 4 && offsetof(WatchWords, step) == WATCH_STEP * 4 &&
              sizeof(WatchWords) == WATCH_WORDS * 4);

// The frame's read-back, one host-visible buffer: reduce_final.comp's two vec4 (its Result
// block), the adaptive iteration count copied from check_converged's indirect buffer, and
// watch.comp's words.
struct FrameResult {
  float mean_compression, max_compression, kinetic_energy, max_speed;  // reduce_final's `result`
  float potential_energy, solid_work, unused_energy[2];                // and its `energy`
  uint32_t iterations, unused[3];
  WatchWords watch;
};

// A prefix sum's levels (gpu_scan.hpp): [0] the values and the total, then the block sums.
struct ScanBuffers {
  std::vector<uint32_t> level_entries;
  std::vector<uint64_t> levels;  // bytes of each level: whole scan blocks
  uint64_t total() const;
};
ScanBuffers plan_scan(uint64_t values);  // `values` and one more entry for the total

// The grid's counting sort (gpu_grid.hpp): each particle's cell and rank, its cells' order, and
// the scan of a count per cell.
struct GridBuffers {
  uint64_t cell = 0, rank = 0, order = 0;  // order: each cell's particles by slot (grid_order.comp)
  ScanBuffers scan;
};

struct SolverBuffers {
  static constexpr int kParticleVec4s = 5;  // x, v, x_pred and two spares, whose roles swap
  static constexpr int kIdArrays = 2;       // the particles' ids before and after a sort
  uint64_t particle_vec4 = 0;               // each of those, and (x_pred, lambda)
  uint64_t id = 0, rho = 0;
  uint64_t neighbour_count = 0, neighbour_list = 0;  // counts then the overflow and near lists; entries
  uint64_t x_lambda_spare = 0, curl = 0;             // 0 where the scene has no smoothing, no vorticity
  uint64_t partials = 0, obstacles = 0, watch = 0, overflow_groups = 0;
  uint64_t work = 0;  // the moving solids' work per particle slot (a word where none moves)
  uint64_t crease_records = 0;  // four vec4 a particle where a mesh is among the solids, else one record
  // Each of the two arrays of the particles' distances from every obstacle (keeps_distances),
  // at the positions a pass reads and those it writes; a word where the step keeps none.
  uint64_t distances = 0;
  uint64_t adaptive_words = 0;  // each of check_converged's three buffers; 0 without adaptive iterations
  uint64_t coarse_sums = 0, coarse_phi = 0, coarse_grad = 0, coarse_open = 0;  // the coarse correction's nodes; 0 where it is off
  uint64_t result = sizeof(FrameResult);
  // The outputs' (FrameOutputs), 0 while off: the drawn shapes (the smoothed positions take a
  // spare vec4 array); white water's count (two words: white_water_birth.comp) and two lists
  // (the living, and where they move before the survivors are packed back), each (x, life) and
  // (v, tag) arrays.
  // Their order is fixed by prefix sums: which living survive (over the capacity) and how many
  // each fluid particle bears (over the particles).
  static constexpr int kWhiteLists = 2;
  uint64_t shape = 0, white_count = 0, white_array = 0;
  ScanBuffers white_survivors, white_births;
  // The drains' (a scene without them holds none): their boxes, the drained particles' (x, v), the
  // counts kept and drained, and which particles stay, scanned into their slots (drain_*.comp).
  uint64_t drains = 0, drained = 0, drain_counts = 0;
  ScanBuffers drain_keep;
  // The bodies' push sums (contract.h's BODY_PUSH_WORDS a body), on the device and a host copy to
  // read, and a host copy of the coarse gradient; none without bodies.
  uint64_t body_push = 0;
  GridBuffers grid;

  uint64_t total() const;
  uint64_t white_water() const;  // white water's buffers, of the total
  uint64_t largest() const;  // one buffer, against the storage buffer range
};

constexpr uint32_t kReduceThreads = 256;  // reduce_stats.comp and reduce_final.comp: particles per partial sum
// The partial sums reduce_stats.comp writes for `particles`.
inline uint64_t partial_count(uint64_t particles) { return (particles + kReduceThreads - 1) / kReduceThreads; }
constexpr uint32_t kScanBlock = 1024;     // values per workgroup in scan_blocks.comp (64 threads x 16)
// Up to this many blocks scan in one workgroup, in one dispatch (gpu_grid.cpp).
constexpr uint32_t kOneGroupBlocks = 32;

// The words per particle of the neighbour list buffer for `capacity` entries: whole groups
// of four (shaders/neighbour_lists.comp), one group without lists.
inline uint32_t list_words(uint32_t capacity) { return 4 * ((capacity + 3) / 4 + (capacity == 0)); }

// Whether the step keeps each particle's distance from every obstacle, from the lists pass on,
// for the near readers (shaders/solids.glsl, DISTANCES): where it has obstacles and lists, and no
// bodies, which move between its passes.
inline bool keeps_distances(const Derived& d) {
  return !d.obstacles.empty() && d.neighbour_capacity > 0 && d.bodies.empty();
}

// `d.neighbour_capacity` as the run will use it (neighbour_capacity_on).
SolverBuffers plan_buffers(const Derived& d, uint64_t particles, FrameOutputs outputs = {});

}  // namespace pbflow
