#pragma once
// A compute shader's interface read back from its SPIR-V, as Granite does: the host names
// what it binds and specialises, and the slot numbers, descriptor types, texel formats and
// constant ids stay where the GLSL declares them. The names come from the shader's debug
// names (glslc -g, cmake/embed.cmake).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pbflow::vk {

enum class ConstantType { Bool, Integer, Float };  // a specialisation constant's scalar type

struct ShaderLayout {
  struct Binding {
    uint32_t slot;
    // The variable's name; for an anonymous buffer block, the block's name in snake case
    // (`buffer XPred { vec4 x_pred[]; }` binds as x_pred).
    std::string name;
    VkDescriptorType type;  // storage buffer, or storage texel buffer (a readonly imageBuffer)
    VkFormat format;        // the texel buffer's format; VK_FORMAT_UNDEFINED for a storage buffer
  };
  struct Constant {
    uint32_t id;
    std::string name;
    ConstantType type;
  };
  std::vector<Binding> bindings;    // by slot
  std::vector<Constant> constants;  // by id; the workgroup size (local_size_x_id = 0) is not one of them
  struct Member {
    std::string name;
    uint32_t offset;
  };
  uint32_t push_bytes = 0;           // the push-constant block's size: its last member's end; 0 where none is used
  std::vector<Member> push_members;  // its members in order, with their byte offsets
};

// Throws vk::Error on words that are not SPIR-V, on a descriptor set other than 0 and on a
// descriptor kind the compute programs do not use.
ShaderLayout reflect_layout(std::span<const uint32_t> spirv);

}  // namespace pbflow::vk
