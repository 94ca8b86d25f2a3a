#pragma once
// A compute program: one embedded shader, its buffer bindings (pushed per dispatch with
// VK_KHR_push_descriptor) and a push-constant block. Move-only; its Vulkan objects are shared
// with the programs made alike where the context keeps programs (ProgramCache).
// A binding is a storage buffer, or, where the shader declares it a `readonly imageBuffer`,
// a storage texel buffer the shader only reads with imageLoad: the neighbour loops gather
// through it, for a CPU device turns every storage-buffer load into a loop over its SIMD lanes
// with a branch per lane, while an image load is one vector gather, inlined. (A texelFetch from
// a uniform texel buffer is a gather too, but a call into a sampling function that spills the
// live registers.) The measurement: docs/performance.md, "Measurements behind the code".
#include <vulkan/vulkan.h>

#include <bit>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vk/program_cache.hpp"
#include "vk/spirv_layout.hpp"

namespace pbflow::vk {

class Context;

// A specialisation constant the host sets, by the name the shader declares it with, and of
// the shader's type (a float where the shader says uint is refused, not reinterpreted).
struct Constant {
  Constant(std::string_view n, float v) : name(n), value(std::bit_cast<uint32_t>(v)), type(ConstantType::Float) {}
  Constant(std::string_view n, uint32_t v) : name(n), value(v), type(ConstantType::Integer) {}
  Constant(std::string_view n, int v) : name(n), value(uint32_t(v)), type(ConstantType::Integer) {}
  Constant(std::string_view n, bool v) : name(n), value(v ? 1u : 0u), type(ConstantType::Bool) {}
  std::string_view name;
  uint32_t value;  // its 32 bits
  ConstantType type;
};

class Program {
 public:
  static constexpr size_t kMaxBindings = 16;
  static constexpr uint32_t kGuaranteedPushBytes = 128;  // maxPushConstantsSize's least (Vulkan 1.x)

  Program() = default;
  // shader: name of shaders/<shader>.comp, whose bindings and constants are read from its
  // SPIR-V (vk/spirv_layout.hpp); push_bytes: size of the host's push-constant struct, which
  // must be the shader's block's (read from the SPIR-V; checked, as its 128-byte limit is);
  // workgroup_size: local_size_x (specialisation constant 0), 0 for the device's choice;
  // constants: the shader's own constants, by name; offered: constants any program may declare
  // (the solver's keys), set where the shader declares them. A constant the shader lacks, one
  // of another type, or one it declares and neither list holds, throws: the sides never drift.
  Program(const Context& ctx, std::string_view shader, uint32_t push_bytes, uint32_t workgroup_size = 0,
          std::span<const Constant> constants = {}, std::span<const Constant> offered = {});
  Program(Program&&) noexcept = default;
  Program& operator=(Program&&) noexcept = default;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  VkPipeline pipeline() const { return compiled_ ? compiled_->pipeline : VK_NULL_HANDLE; }
  VkPipelineLayout layout() const { return compiled_ ? compiled_->layout : VK_NULL_HANDLE; }
  const std::vector<ShaderLayout::Binding>& bindings() const { return bindings_; }
  // The index in bindings() of the binding the shader names `name`; throws if it has none.
  size_t binding(std::string_view name) const;
  // Whether the shader has a binding named `name` (one it declares but never reads has none).
  bool reads(std::string_view name) const;
  uint32_t push_bytes() const { return push_bytes_; }
  uint32_t workgroup_size() const { return workgroup_size_; }
  const std::string& name() const { return name_; }

 private:
  std::shared_ptr<const CompiledProgram> compiled_;  // shared where the context keeps programs
  std::string name_;
  std::vector<ShaderLayout::Binding> bindings_;
  uint32_t push_bytes_ = 0, workgroup_size_ = 0;
};

}  // namespace pbflow::vk
