#pragma once
// A small compute command API in the manner of Granite: set_program, bind, push,
// dispatch. Every dispatch is followed by a barrier, since each pass of the solver
// reads what the previous one wrote.
#include <vulkan/vulkan.h>

#include <array>
#include <functional>
#include <string_view>

#include "vk/program.hpp"

namespace pbflow::vk {

class Context;
class Buffer;

class CommandList {
 public:
  explicit CommandList(const Context& ctx);
  ~CommandList() { release(); }
  CommandList(const CommandList&) = delete;
  CommandList& operator=(const CommandList&) = delete;

  void begin();
  void submit_and_wait();  // ends recording, submits, waits for the GPU to finish

  void set_program(const Program& program);
  // Binds `buffer` to the current program's binding that the shader names `name`
  // (vk/spirv_layout.hpp), as a storage buffer or a texel view as the shader declares it.
  void bind(std::string_view name, const Buffer& buffer);
  // Whether the current program reads a binding named `name`: a shader that never reads what
  // an include declares has no such binding.
  bool reads(std::string_view name) const;
  template <class T>
  void push(const T& constants) { push_bytes(&constants, sizeof(T)); }
  // Runs the program over `invocations` threads (gl_GlobalInvocationID folded to 1D by
  // shaders/common.glsl's thread_index()), then a barrier.
  void dispatch(uint32_t invocations);
  // Group counts from `args` (a VkDispatchIndirectCommand at `offset`, written on the GPU).
  void dispatch_indirect(const Buffer& args, VkDeviceSize offset = 0);
  // The dispatches `record` makes share one barrier at its end: they write disjoint elements
  // (a neighbour pass's variants, each over its own particles), so a GPU may run them at once.
  void disjoint(const std::function<void()>& record);
  // The (x, y) group counts dispatch() uses for `invocations` threads.
  std::array<uint32_t, 2> groups(uint32_t invocations, uint32_t workgroup_size) const;
  // Writes `bytes` (a multiple of 4, at most 65536) at `offset` into `buffer`, then a barrier.
  void update(const Buffer& buffer, const void* data, uint32_t bytes, uint32_t offset = 0);

  void fill(const Buffer& buffer, uint32_t value);
  void timestamp(VkQueryPool pool, uint32_t query);
  VkCommandBuffer handle() const { return cb_; }

 private:
  void push_bytes(const void* data, uint32_t bytes);
  void push_descriptors();
  void release() noexcept;

  const Context* ctx_;
  VkCommandBuffer cb_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  const Program* program_ = nullptr;
  bool barrier_held_ = false;  // inside disjoint(): its end places the barrier
  std::array<VkDescriptorBufferInfo, Program::kMaxBindings> bound_{};
  std::array<VkBufferView, Program::kMaxBindings> views_{};  // the texel bindings'
};

}  // namespace pbflow::vk
