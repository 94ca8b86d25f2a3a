#include "gpu/gpu_scan.hpp"

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

GpuScan::GpuScan(const vk::Context& ctx, const ScanBuffers& plan)
    : blocks_(ctx, "scan_blocks", sizeof(ScanPush), kScanThreads),
      add_(ctx, "scan_add", sizeof(uint32_t), kScanThreads),
      level_size_(plan.level_entries) {
  for (uint64_t bytes : plan.levels) levels_.emplace_back(ctx, bytes);
}

void GpuScan::run(vk::CommandList& cmd) const { scan(cmd, 0); }

void GpuScan::scan(vk::CommandList& cmd, size_t level) const {
  const uint32_t n = level_size_[level];
  const bool one_group = blocks(n) <= kOneGroupBlocks;
  const ScanPush push{n, one_group ? blocks(n) : 1};
  cmd.set_program(blocks_);
  cmd.bind("data", levels_[level]);
  cmd.bind("sums", levels_[level + 1]);
  cmd.push(push);
  const uint32_t threads = blocks(n) * kScanThreads;
  cmd.dispatch(one_group ? kScanThreads : threads);
  if (!one_group) {
    scan(cmd, level + 1);
    cmd.set_program(add_);
    cmd.bind("data", levels_[level]);
    cmd.bind("sums", levels_[level + 1]);
    cmd.push(n);
    cmd.dispatch(threads);
  }
}

}  // namespace pbflow
