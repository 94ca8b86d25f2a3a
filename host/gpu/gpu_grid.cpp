#include "gpu/gpu_grid.hpp"

#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {
constexpr uint32_t kScanThreads = 64;
// On a CPU device each dispatch costs more in threads waking than the scan's work, so up to
// kOneGroupBlocks blocks (the peer scene's 18 001 cells are 18) scan in one workgroup, in one
// dispatch; on a GPU a group's few dozen blocks take microseconds (docs/performance.md,
// "Measurements behind the code").
struct ScanPush {
  uint32_t n, blocks;  // values; blocks per workgroup (scan_blocks.comp)
};
uint32_t blocks(uint32_t values) { return (values + kScanBlock - 1) / kScanBlock; }
}  // namespace

GpuGrid::GpuGrid(const vk::Context& ctx, const GridBuffers& plan)
    : count_(ctx, "grid_count", sizeof(SimConstants)),
      scan_blocks_(ctx, "scan_blocks", sizeof(ScanPush), kScanThreads),
      scan_add_(ctx, "scan_add", sizeof(uint32_t), kScanThreads),
      order_(ctx, "grid_order", sizeof(SimConstants)),
      scatter_(ctx, "grid_scatter", sizeof(SimConstants)),
      cell_(ctx, plan.cell),
      rank_(ctx, plan.rank),
      slots_(ctx, plan.order),
      level_size_(plan.level_entries) {
  for (uint64_t bytes : plan.levels) levels_.emplace_back(ctx, bytes);
}

void GpuGrid::scan(vk::CommandList& cmd, size_t level) {
  const uint32_t n = level_size_[level];
  const bool one_group = blocks(n) <= kOneGroupBlocks;
  const ScanPush push{n, one_group ? blocks(n) : 1};
  cmd.set_program(scan_blocks_);
  cmd.bind("data", levels_[level]);
  cmd.bind("sums", levels_[level + 1]);
  cmd.push(push);
  const uint32_t threads = blocks(n) * kScanThreads;
  cmd.dispatch(one_group ? kScanThreads : threads);
  if (!one_group) {
    scan(cmd, level + 1);
    cmd.set_program(scan_add_);
    cmd.bind("data", levels_[level]);
    cmd.bind("sums", levels_[level + 1]);
    cmd.push(n);
    cmd.dispatch(threads);
  }
}

void GpuGrid::build(vk::CommandList& cmd, const SimConstants& sim, Particles in, Particles out) {
  cmd.fill(levels_[0], 0);
  cmd.set_program(count_);
  cmd.bind("x", *in.x);
  cmd.bind("cell", cell_);
  cmd.bind("rank", rank_);
  cmd.bind("count", levels_[0]);
  cmd.push(sim);
  cmd.dispatch(sim.count);

  scan(cmd, 0);

  cmd.set_program(order_);
  cmd.bind("cell", cell_);
  cmd.bind("rank", rank_);
  cmd.bind("cell_start", levels_[0]);
  cmd.bind("order", slots_);
  cmd.push(sim);
  cmd.dispatch(sim.count);

  cmd.set_program(scatter_);
  cmd.bind("order", slots_);
  cmd.bind("cell", cell_);
  cmd.bind("cell_start", levels_[0]);
  cmd.bind("x_in", *in.x);
  cmd.bind("payload_in", *in.payload);
  cmd.bind("id_in", *in.id);
  cmd.bind("x_out", *out.x);
  cmd.bind("payload_out", *out.payload);
  cmd.bind("id_out", *out.id);
  cmd.push(sim);
  cmd.dispatch(sim.count);
}

}  // namespace pbflow
