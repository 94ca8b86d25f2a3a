#include "vk/program.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vk/check.hpp"
#include "vk/context.hpp"
#include "vk/shader_library.hpp"

namespace pbflow::vk {

namespace {
const Constant* find_constant(std::span<const Constant> constants, std::string_view name) {
  auto c = std::ranges::find(constants, name, &Constant::name);
  return c == constants.end() ? nullptr : &*c;
}

struct Specialisation {
  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values;
};

// Constant 0 is local_size_x; the shader's own constants follow by id, each set by name from
// `constants` (which it must all declare) or else `offered`, in the type it declares.
Specialisation specialise(const std::string& program, const std::vector<ShaderLayout::Constant>& declared,
                          uint32_t workgroup_size, std::span<const Constant> constants, std::span<const Constant> offered) {
  Specialisation s{{{0, 0, sizeof(uint32_t)}}, {workgroup_size}};
  for (const Constant& c : constants)
    if (std::ranges::find(declared, c.name, &ShaderLayout::Constant::name) == declared.end())
      throw Error("program " + program + " declares no constant " + std::string(c.name));
  for (const ShaderLayout::Constant& c : declared) {
    const Constant* given = find_constant(constants, c.name);
    if (!given) given = find_constant(offered, c.name);
    if (!given) throw Error("program " + program + ": constant " + c.name + " was not set");
    if (given->type != c.type)
      throw Error("program " + program + ": constant " + c.name + " is set as another type than the shader declares");
    s.entries.push_back({c.id, uint32_t(s.values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
    s.values.push_back(given->value);
  }
  return s;
}

// The key a program's Vulkan objects are kept by: what they are made from.
std::string program_key(const std::string& name, uint32_t push_bytes, const Specialisation& s) {
  std::string key = name + "/" + std::to_string(push_bytes);
  for (size_t k = 0; k < s.values.size(); ++k)
    key += "/" + std::to_string(s.entries[k].constantID) + "=" + std::to_string(s.values[k]);
  return key;
}

// The descriptor set layout, pipeline layout and pipeline of a program.
std::shared_ptr<const CompiledProgram> compile(const Context& ctx, std::span<const uint32_t> words,
                                               const std::vector<ShaderLayout::Binding>& bindings, uint32_t push_bytes,
                                               const Specialisation& spec_values) {
  auto c = std::make_shared<CompiledProgram>(ctx.device());
  std::vector<VkDescriptorSetLayoutBinding> slots;
  for (const ShaderLayout::Binding& b : bindings) slots.push_back({b.slot, b.type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  VkDescriptorSetLayoutCreateInfo set{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  set.bindingCount = uint32_t(slots.size());
  set.pBindings = slots.data();
  VK_CHECK(vkCreateDescriptorSetLayout(ctx.device(), &set, nullptr, &c->set_layout));

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &c->set_layout;
  layout.pushConstantRangeCount = push_bytes ? 1 : 0;
  layout.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(ctx.device(), &layout, nullptr, &c->layout));

  VkShaderModuleCreateInfo code{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  code.codeSize = words.size_bytes();
  code.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(ctx.device(), &code, nullptr, &module));
  const auto& [entries, values] = spec_values;
  VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), values.size() * sizeof(uint32_t), values.data()};
  VkComputePipelineCreateInfo pipe{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pipe.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  pipe.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipe.stage.module = module;
  pipe.stage.pName = "main";
  pipe.stage.pSpecializationInfo = &spec;
  pipe.layout = c->layout;
  const VkResult made = vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &pipe, nullptr, &c->pipeline);
  vkDestroyShaderModule(ctx.device(), module, nullptr);  // the pipeline keeps what it needs
  VK_CHECK(made);
  return c;
}
}  // namespace

Program::Program(const Context& ctx, std::string_view shader, uint32_t push_bytes, uint32_t workgroup_size,
                 std::span<const Constant> constants, std::span<const Constant> offered)
    : name_(shader),
      push_bytes_(push_bytes),
      workgroup_size_(workgroup_size ? workgroup_size : ctx.workgroup_size()) {
  const std::span<const uint32_t> words = shaders::spirv(shader);
  ShaderLayout layout = reflect_layout(words);
  bindings_ = std::move(layout.bindings);
  // The shader's push block is the size; the host's struct must match it, and every device must hold it.
  if (layout.push_bytes > kGuaranteedPushBytes)
    throw Error("program " + name_ + ": its push-constant block takes " + std::to_string(layout.push_bytes) +
                " bytes, past the " + std::to_string(kGuaranteedPushBytes) + " every Vulkan device holds");
  if (layout.push_bytes != 0 && layout.push_bytes != push_bytes)
    throw Error("program " + name_ + ": the shader's push-constant block is " + std::to_string(layout.push_bytes) +
                " bytes and the host's " + std::to_string(push_bytes) + ": the GLSL block and its C++ mirror disagree");
  if (bindings_.size() > kMaxBindings) throw Error("program " + name_ + " has more than " + std::to_string(kMaxBindings) + " bindings");
  const Specialisation spec_values = specialise(name_, layout.constants, workgroup_size_, constants, offered);
  ProgramCache* kept = ctx.kept_programs();
  const std::string key = kept ? program_key(name_, push_bytes, spec_values) : std::string();
  if (kept) compiled_ = kept->find(key);
  if (compiled_) return;
  compiled_ = compile(ctx, words, bindings_, push_bytes, spec_values);
  if (kept) kept->keep(key, compiled_);
}

bool Program::reads(std::string_view name) const {
  return std::ranges::find(bindings_, name, &ShaderLayout::Binding::name) != bindings_.end();
}

size_t Program::binding(std::string_view name) const {
  auto b = std::ranges::find(bindings_, name, &ShaderLayout::Binding::name);
  if (b == bindings_.end()) throw Error("program " + name_ + " has no binding named " + std::string(name));
  return size_t(b - bindings_.begin());
}

}  // namespace pbflow::vk
