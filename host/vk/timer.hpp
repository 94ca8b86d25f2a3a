#pragma once
// GPU time from timestamp queries: marks written into a command list, read after it ran.
#include <vulkan/vulkan.h>

#include <vector>

namespace pbflow::vk {

class Context;
class CommandList;

class GpuTimer {
 public:
  GpuTimer(const Context& ctx, uint32_t capacity);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  bool available() const { return pool_ != VK_NULL_HANDLE; }  // false: the device has no timestamps
  uint32_t capacity() const { return capacity_; }
  void reset(CommandList& cmd);                                 // before the first mark of a submission
  uint32_t mark(CommandList& cmd);                              // returns the mark's index
  // Milliseconds between marks a and b of the last submission (after it completed).
  std::vector<double> read_ms() const;  // all marks, relative to mark 0

 private:
  const Context* ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t capacity_, used_ = 0;
  double period_ns_ = 1.0;
};

}  // namespace pbflow::vk
