#include "vk/commands.hpp"

#include <string>

#include "vk/buffer.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"
#include "vk/program.hpp"

namespace pbflow::vk {

CommandList::CommandList(const Context& ctx) : ctx_(&ctx) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = ctx.command_pool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(ctx.device(), &alloc, &cb_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  try {
    VK_CHECK(vkCreateFence(ctx.device(), &fence, nullptr, &fence_));
  } catch (...) {
    release();
    throw;
  }
}

void CommandList::release() noexcept {
  if (fence_) vkDestroyFence(ctx_->device(), fence_, nullptr);
  if (cb_) vkFreeCommandBuffers(ctx_->device(), ctx_->command_pool(), 1, &cb_);
  fence_ = VK_NULL_HANDLE;
  cb_ = VK_NULL_HANDLE;
}

void CommandList::begin() {
  VK_CHECK(vkResetCommandBuffer(cb_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cb_, &begin));
  program_ = nullptr;
}

void CommandList::submit_and_wait() {
  VK_CHECK(vkEndCommandBuffer(cb_));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb_;
  VK_CHECK(vkResetFences(ctx_->device(), 1, &fence_));
  VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &submit, fence_));
  VK_CHECK(vkWaitForFences(ctx_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
}

void CommandList::set_program(const Program& program) {
  if (program.pipeline() == VK_NULL_HANDLE) throw Error("set_program: a program that was never built");
  program_ = &program;
  bound_.fill({});
  views_.fill(VK_NULL_HANDLE);
  vkCmdBindPipeline(cb_, VK_PIPELINE_BIND_POINT_COMPUTE, program.pipeline());
}

bool CommandList::reads(std::string_view name) const { return program_ && program_->reads(name); }

void CommandList::bind(std::string_view name, const Buffer& buffer) {
  if (!program_) throw Error("bind(" + std::string(name) + ") without a program");
  const size_t i = program_->binding(name);
  bound_[i] = {buffer.handle(), 0, VK_WHOLE_SIZE};
  if (VkFormat format = program_->bindings()[i].format) views_[i] = buffer.view(format);
}

void CommandList::push_bytes(const void* data, uint32_t bytes) {
  if (!program_ || bytes != program_->push_bytes())
    throw Error("push constants of " + std::to_string(bytes) + " bytes do not match program " +
                (program_ ? program_->name() : std::string("(none)")));
  vkCmdPushConstants(cb_, program_->layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, data);
}

void CommandList::push_descriptors() {
  const auto& bindings = program_->bindings();
  std::array<VkWriteDescriptorSet, Program::kMaxBindings> writes{};
  for (size_t i = 0; i < bindings.size(); ++i) {
    if (!bound_[i].buffer) throw Error("program " + program_->name() + ": " + bindings[i].name + " was not bound");
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstBinding = bindings[i].slot;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = bindings[i].type;
    if (bindings[i].format)
      writes[i].pTexelBufferView = &views_[i];
    else
      writes[i].pBufferInfo = &bound_[i];
  }
  ctx_->push_descriptor_set(cb_, VK_PIPELINE_BIND_POINT_COMPUTE, program_->layout(), 0, uint32_t(bindings.size()),
                            writes.data());
}

std::array<uint32_t, 2> CommandList::groups(uint32_t invocations, uint32_t workgroup_size) const {
  // Large particle counts can exceed the group-count limit in x: fold the rest into y.
  uint32_t groups = (invocations + workgroup_size - 1) / workgroup_size;
  uint32_t gx = std::min(groups, ctx_->limits().maxComputeWorkGroupCount[0]);
  return {gx, gx ? (groups + gx - 1) / gx : 0};
}

void CommandList::dispatch(uint32_t invocations) {
  if (!program_) throw Error("dispatch without a program");
  if (invocations == 0) return;
  push_descriptors();
  auto [gx, gy] = groups(invocations, program_->workgroup_size());
  vkCmdDispatch(cb_, gx, gy, 1);
  if (!barrier_held_) memory_barrier(cb_);
}

void CommandList::dispatch_indirect(const Buffer& args, VkDeviceSize offset) {
  if (!program_) throw Error("dispatch_indirect without a program");
  push_descriptors();
  vkCmdDispatchIndirect(cb_, args.handle(), offset);
  if (!barrier_held_) memory_barrier(cb_);
}

void CommandList::disjoint(const std::function<void()>& record) {
  if (barrier_held_) throw Error("disjoint dispatches nested");
  {
    barrier_held_ = true;
    struct Release {
      bool& held;
      ~Release() { held = false; }
    } release{barrier_held_};
    record();
  }
  memory_barrier(cb_);
}

void CommandList::update(const Buffer& buffer, const void* data, uint32_t bytes, uint32_t offset) {
  constexpr uint32_t kMostBytes = 65536;  // vkCmdUpdateBuffer's limit per call
  for (uint32_t done = 0; done < bytes; done += kMostBytes)
    vkCmdUpdateBuffer(cb_, buffer.handle(), offset + done, std::min(kMostBytes, bytes - done),
                      static_cast<const char*>(data) + done);
  memory_barrier(cb_);
}

void CommandList::fill(const Buffer& buffer, uint32_t value) {
  vkCmdFillBuffer(cb_, buffer.handle(), 0, VK_WHOLE_SIZE, value);
  memory_barrier(cb_);
}

void CommandList::timestamp(VkQueryPool pool, uint32_t query) {
  vkCmdWriteTimestamp(cb_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool, query);
}

}  // namespace pbflow::vk
