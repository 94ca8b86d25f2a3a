#pragma once
// An exclusive prefix sum over a buffer of uints on the GPU, in place, of any length: a
// block-wise scan, then the blocks' sums scanned recursively and added back (scan_blocks.comp,
// scan_add.comp). Its order of additions is fixed, so its result is the same on every run.
#include <vector>

#include "gpu/buffer_plan.hpp"
#include "vk/buffer.hpp"
#include "vk/program.hpp"

namespace pbflow {

namespace vk {
class CommandList;
class Context;
}  // namespace vk

class GpuScan {
 public:
  GpuScan() = default;
  GpuScan(const vk::Context& ctx, const ScanBuffers& plan);
  // data()'s `entries` values become their exclusive prefix sums; the last entry, kept 0 by the
  // caller, becomes the total.
  void run(vk::CommandList& cmd) const;
  const vk::Buffer& data() const { return levels_.front(); }

 private:
  void scan(vk::CommandList& cmd, size_t level) const;

  vk::Program blocks_, add_;
  std::vector<vk::Buffer> levels_;    // [0]: the values, scanned in place; then block sums
  std::vector<uint32_t> level_size_;  // entries in each level
};

}  // namespace pbflow
