#include "vk/timer.hpp"

#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow::vk {

GpuTimer::GpuTimer(const Context& ctx, uint32_t capacity) : ctx_(&ctx), capacity_(capacity) {
  if (!ctx.info().timestamps) return;
  period_ns_ = ctx.limits().timestampPeriod;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = capacity;
  VK_CHECK(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_));
}

GpuTimer::~GpuTimer() {
  if (pool_) vkDestroyQueryPool(ctx_->device(), pool_, nullptr);
}

void GpuTimer::reset(CommandList& cmd) {
  used_ = 0;
  if (pool_) vkCmdResetQueryPool(cmd.handle(), pool_, 0, capacity_);
}

uint32_t GpuTimer::mark(CommandList& cmd) {
  if (used_ >= capacity_) throw Error("GpuTimer: more marks than its capacity");
  if (pool_) cmd.timestamp(pool_, used_);
  return used_++;
}

std::vector<double> GpuTimer::read_ms() const {
  std::vector<double> ms(used_, 0.0);
  if (!pool_ || used_ == 0) return ms;
  std::vector<uint64_t> ticks(used_);
  VK_CHECK(vkGetQueryPoolResults(ctx_->device(), pool_, 0, used_, ticks.size() * sizeof(uint64_t), ticks.data(),
                                 sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  for (uint32_t i = 0; i < used_; ++i) ms[i] = double(ticks[i] - ticks[0]) * period_ns_ * 1e-6;
  return ms;
}

}  // namespace pbflow::vk
