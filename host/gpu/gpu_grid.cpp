#include "gpu/gpu_grid.hpp"

#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {
constexpr uint32_t kScanBlock = 1024;   // values per workgroup in scan_blocks.comp (64 threads x 16)
constexpr uint32_t kScanThreads = 64;
// Up to this many blocks scan in one workgroup, in one dispatch (the peer's 18 001 cells
// are 18): on lavapipe each dispatch costs ~0.05 ms of threads waking, more than the
// scan's work; on a GPU a group's few dozen blocks take microseconds.
constexpr uint32_t kOneGroupBlocks = 32;
struct ScanPush {
  uint32_t n, blocks;  // values; blocks per workgroup (scan_blocks.comp)
};
uint32_t blocks(uint32_t values) { return (values + kScanBlock - 1) / kScanBlock; }
}  // namespace

GpuGrid::GpuGrid(const vk::Context& ctx, const SimConstants& sim)
    : count_(ctx, "grid_count", 4, sizeof(SimConstants)),
      scan_blocks_(ctx, "scan_blocks", 2, sizeof(ScanPush), kScanThreads),
      scan_add_(ctx, "scan_add", 2, sizeof(uint32_t), kScanThreads),
      scatter_(ctx, "grid_scatter", 9, sizeof(SimConstants)),
      cell_(ctx, sim.count * sizeof(uint32_t)),
      rank_(ctx, sim.count * sizeof(uint32_t)) {
  // One more entry than cells: after the exclusive scan it holds the particle count,
  // so that cell c's particles are [start[c], start[c + 1]) for every c.
  uint32_t size = uint32_t(sim.grid.x) * sim.grid.y * sim.grid.z + 1;
  for (;;) {
    level_size_.push_back(size);
    levels_.emplace_back(ctx, blocks(size) * kScanBlock * sizeof(uint32_t));  // the scan moves whole blocks
    if (size == 1) break;
    // The next level holds this one's block sums, or only its total where it scans in one group.
    size = blocks(size) <= kOneGroupBlocks ? 1 : blocks(size);
  }
}

void GpuGrid::scan(vk::CommandList& cmd, size_t level) {
  const uint32_t n = level_size_[level];
  const bool one_group = blocks(n) <= kOneGroupBlocks;
  const ScanPush push{n, one_group ? blocks(n) : 1};
  cmd.set_program(scan_blocks_);
  cmd.bind(0, levels_[level]);
  cmd.bind(1, levels_[level + 1]);
  cmd.push(push);
  const uint32_t threads = blocks(n) * kScanThreads;
  cmd.dispatch(one_group ? kScanThreads : threads);
  if (!one_group) {
    scan(cmd, level + 1);
    cmd.set_program(scan_add_);
    cmd.bind(0, levels_[level]);
    cmd.bind(1, levels_[level + 1]);
    cmd.push(n);
    cmd.dispatch(threads);
  }
}

void GpuGrid::build(vk::CommandList& cmd, const SimConstants& sim, Particles in, Particles out) {
  cmd.fill(levels_[0], 0);
  cmd.set_program(count_);
  cmd.bind(0, *in.x);
  cmd.bind(1, cell_);
  cmd.bind(2, rank_);
  cmd.bind(3, levels_[0]);
  cmd.push(sim);
  cmd.dispatch(sim.count);

  scan(cmd, 0);

  cmd.set_program(scatter_);
  cmd.bind(0, cell_);
  cmd.bind(1, rank_);
  cmd.bind(2, levels_[0]);
  cmd.bind(3, *in.x);
  cmd.bind(4, *in.payload);
  cmd.bind(5, *in.id);
  cmd.bind(6, *out.x);
  cmd.bind(7, *out.payload);
  cmd.bind(8, *out.id);
  cmd.push(sim);
  cmd.dispatch(sim.count);
}

}  // namespace pbflow
