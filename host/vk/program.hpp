#pragma once
// A compute program: one embedded shader, its buffer bindings (pushed per dispatch with
// VK_KHR_push_descriptor) and a push-constant block. Move-only.
// A binding is a storage buffer, or, where the program names it a texel binding, a
// storage texel buffer the shader only reads (a `readonly imageBuffer` read with
// imageLoad): the neighbour loops gather through it, for llvmpipe turns every
// storage-buffer load into a loop over its SIMD lanes with a branch per lane, while an
// image load is one vector gather, inlined. (A texelFetch from a uniform texel buffer is
// a gather too, but a call into a sampling function that spills the live registers; the
// image loads made a peer run 0.90-0.91x the wall time: bench/results/throughput_lavapipe.md.)
#include <vulkan/vulkan.h>

#include <array>
#include <span>
#include <string>
#include <string_view>

namespace pbflow::vk {

class Context;

// A binding read as a storage texel buffer of `format`.
struct TexelBinding {
  uint32_t binding;
  VkFormat format;
};

class Program {
 public:
  static constexpr uint32_t kMaxBindings = 12;

  Program() = default;
  // shader: name of shaders/<shader>.comp; bindings: storage buffers 0..bindings-1;
  // push_bytes: size of the push-constant block; workgroup_size: local_size_x
  // (specialisation constant 0), 0 for the device's choice; constants: the shader's
  // own specialisation constants 1, 2, ... (32-bit each); texels: the bindings that are
  // storage texel buffers.
  Program(const Context& ctx, std::string_view shader, uint32_t bindings, uint32_t push_bytes,
          uint32_t workgroup_size = 0, std::span<const uint32_t> constants = {},
          std::span<const TexelBinding> texels = {});
  ~Program() { release(); }
  Program(Program&& o) noexcept { *this = std::move(o); }
  Program& operator=(Program&& o) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  VkPipeline pipeline() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  uint32_t bindings() const { return bindings_; }
  uint32_t push_bytes() const { return push_bytes_; }
  uint32_t workgroup_size() const { return workgroup_size_; }
  // The format of a texel binding; VK_FORMAT_UNDEFINED for a storage buffer.
  VkFormat texel_format(uint32_t binding) const { return texel_formats_[binding]; }
  const std::string& name() const { return name_; }

 private:
  void release() noexcept;

  const Context* ctx_ = nullptr;
  std::string name_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  uint32_t bindings_ = 0, push_bytes_ = 0, workgroup_size_ = 0;
  std::array<VkFormat, kMaxBindings> texel_formats_{};
};

}  // namespace pbflow::vk
