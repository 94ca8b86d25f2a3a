#include "vk/spirv_layout.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <map>

#include "vk/check.hpp"

namespace pbflow::vk {

namespace {

// The few SPIR-V opcodes, decorations and enumerants the layout needs (SPIR-V 1.5 spec, 3.x).
enum Op : uint32_t {
  OpName = 5,
  OpTypeInt = 21,
  OpTypeFloat = 22,
  OpTypeVector = 23,
  OpTypeImage = 25,
  OpTypeArray = 28,
  OpTypeStruct = 30,
  OpTypePointer = 32,
  OpConstant = 43,
  OpSpecConstantTrue = 48,
  OpSpecConstantFalse = 49,
  OpSpecConstant = 50,
  OpVariable = 59,
  OpDecorate = 71,
  OpMemberDecorate = 72,
  OpMemberName = 6,
};
enum Decoration : uint32_t { SpecId = 1, ArrayStride = 6, Binding = 33, DescriptorSet = 34, Offset = 35 };
enum StorageClass : uint32_t { UniformConstant = 0, PushConstant = 9, StorageBuffer = 12 };

// The types a push-constant block is made of, enough to size it: scalars, vectors, arrays and
// structs with their members' offsets.
struct Types {
  std::map<uint32_t, uint32_t> scalar_bytes, constant;
  std::map<uint32_t, std::pair<uint32_t, uint32_t>> vector, array;  // component/element type, count/length id
  std::map<uint32_t, std::vector<uint32_t>> members;
  std::map<uint32_t, std::map<uint32_t, uint32_t>> offsets;  // struct -> member -> byte offset
  std::map<uint32_t, uint32_t> stride;

  uint32_t bytes(uint32_t type) const {
    if (auto s = scalar_bytes.find(type); s != scalar_bytes.end()) return s->second;
    if (auto v = vector.find(type); v != vector.end()) return v->second.second * bytes(v->second.first);
    if (auto a = array.find(type); a != array.end()) {
      const auto given = stride.find(type);
      return constant.at(a->second.second) * (given != stride.end() ? given->second : bytes(a->second.first));
    }
    if (auto m = members.find(type); m != members.end()) {
      uint32_t end = 0;
      for (uint32_t k = 0; k < m->second.size(); ++k) end = std::max(end, offsets.at(type).at(k) + bytes(m->second[k]));
      return end;
    }
    throw Error("shader layout: a push-constant member of a type the programs do not use");
  }
};
constexpr uint32_t kMagic = 0x07230203, kDimBuffer = 5, kSampledStorage = 2, kHeaderWords = 5;

VkFormat texel_format(uint32_t spirv_format) {
  switch (spirv_format) {
    case 1: return VK_FORMAT_R32G32B32A32_SFLOAT;  // Rgba32f
    case 3: return VK_FORMAT_R32_SFLOAT;           // R32f
    case 30: return VK_FORMAT_R32G32B32A32_UINT;   // Rgba32ui
    case 33: return VK_FORMAT_R32_UINT;            // R32ui
    default: throw Error("shader layout: an image format the programs do not use (" + std::to_string(spirv_format) + ")");
  }
}

std::string literal_string(std::span<const uint32_t> words) {
  const char* text = reinterpret_cast<const char*>(words.data());
  return std::string(text, strnlen(text, words.size_bytes()));
}

// A block's name as the host binds it: XLambdaOut -> x_lambda_out.
std::string snake_case(const std::string& block) {
  std::string name;
  for (char c : block) {
    if (std::isupper(static_cast<unsigned char>(c)) && !name.empty()) name += '_';
    name += char(std::tolower(static_cast<unsigned char>(c)));
  }
  return name;
}

// What reflection reads of a module: names, decorations, types and variables by result id.
struct Module {
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, std::map<uint32_t, std::string>> member_names;  // struct -> member -> name
  std::map<uint32_t, uint32_t> slot, set, spec_id, pointee;
  std::map<uint32_t, VkFormat> texel_images;  // storage image buffers, by type id
  struct Variable {
    uint32_t pointer_type, id, storage;
  };
  std::vector<Variable> variables;
  std::map<uint32_t, ConstantType> spec_constants;  // by result id
  std::map<uint32_t, ConstantType> scalar_type;
  Types types;

  explicit Module(std::span<const uint32_t> spirv);  // reads every instruction it needs
  ShaderLayout layout();  // the bindings, push block and constants from what was read
};

Module::Module(std::span<const uint32_t> spirv) {
  if (spirv.size() < kHeaderWords || spirv[0] != kMagic) throw Error("shader layout: not SPIR-V");
  for (size_t at = kHeaderWords; at < spirv.size();) {
    const uint32_t count = spirv[at] >> 16, op = spirv[at] & 0xffff;
    if (count == 0 || at + count > spirv.size()) throw Error("shader layout: truncated SPIR-V");
    const std::span<const uint32_t> arg = spirv.subspan(at + 1, count - 1);
    switch (op) {
      case OpName: names[arg[0]] = literal_string(arg.subspan(1)); break;
      case OpMemberName: member_names[arg[0]][arg[1]] = literal_string(arg.subspan(2)); break;
      case OpDecorate:
        if (arg[1] == Binding) slot[arg[0]] = arg[2];
        if (arg[1] == DescriptorSet) set[arg[0]] = arg[2];
        if (arg[1] == SpecId) spec_id[arg[0]] = arg[2];
        if (arg[1] == ArrayStride) types.stride[arg[0]] = arg[2];
        break;
      case OpMemberDecorate:
        if (arg[2] == Offset) types.offsets[arg[0]][arg[1]] = arg[3];
        break;
      case OpTypeInt:
      case OpTypeFloat:
        types.scalar_bytes[arg[0]] = arg[1] / 8;
        scalar_type[arg[0]] = op == OpTypeFloat ? ConstantType::Float : ConstantType::Integer;
        break;
      case OpTypeVector: types.vector[arg[0]] = {arg[1], arg[2]}; break;
      case OpTypeArray: types.array[arg[0]] = {arg[1], arg[2]}; break;
      case OpTypeStruct: types.members[arg[0]].assign(arg.begin() + 1, arg.end()); break;
      case OpConstant: types.constant[arg[1]] = arg[2]; break;
      case OpTypeImage:  // result, sampled type, dim, depth, arrayed, ms, sampled, format
        if (arg[2] == kDimBuffer && arg[6] == kSampledStorage) texel_images[arg[0]] = texel_format(arg[7]);
        break;
      case OpTypePointer: pointee[arg[0]] = arg[2]; break;
      case OpVariable: variables.push_back({arg[0], arg[1], arg[2]}); break;
      case OpSpecConstantTrue:
      case OpSpecConstantFalse: spec_constants[arg[1]] = ConstantType::Bool; break;
      case OpSpecConstant: spec_constants[arg[1]] = scalar_type.at(arg[0]); break;
      default: break;
    }
    at += count;
  }
}

// Two variables at one slot are two views of one buffer (solids.glsl reads the obstacles as
// vec4s and their fields as floats): the slot is bound once, by the name declared first.
void merge_views(std::vector<ShaderLayout::Binding>& bindings) {
  std::ranges::stable_sort(bindings, {}, &ShaderLayout::Binding::slot);
  for (size_t k = 1; k < bindings.size(); ++k)
    if (bindings[k].slot == bindings[k - 1].slot && bindings[k].type != bindings[k - 1].type)
      throw Error("shader layout: binding " + std::to_string(bindings[k].slot) + " is declared as two kinds of buffer");
  const auto views = std::ranges::unique(bindings, {}, &ShaderLayout::Binding::slot);
  bindings.erase(views.begin(), views.end());
}

ShaderLayout Module::layout() {
  ShaderLayout layout;
  for (const auto [pointer_type, id, storage] : variables) {
    if (storage == PushConstant) {
      const uint32_t block = pointee[pointer_type];
      layout.push_bytes = types.bytes(block);
      for (uint32_t k = 0; k < types.members[block].size(); ++k)
        layout.push_members.push_back({member_names[block][k], types.offsets[block][k]});
    }
    if (!slot.count(id)) continue;
    if (set[id] != 0) throw Error("shader layout: a descriptor set other than 0");
    ShaderLayout::Binding b{slot[id], names[id], VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_FORMAT_UNDEFINED};
    const uint32_t type = pointee[pointer_type];
    if (storage == StorageBuffer) {
      if (b.name.empty()) b.name = snake_case(names[type]);
    } else if (storage == UniformConstant && texel_images.count(type)) {
      b.type = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
      b.format = texel_images[type];
    } else {
      throw Error("shader layout: binding " + std::to_string(b.slot) + " is neither a storage buffer nor a storage image buffer");
    }
    if (b.name.empty()) throw Error("shader layout: binding " + std::to_string(b.slot) + " has no name (compile with -g)");
    layout.bindings.push_back(std::move(b));
  }
  for (const auto& [id, type] : spec_constants)
    if (spec_id.count(id) && spec_id[id] != 0) layout.constants.push_back({spec_id[id], names[id], type});
  merge_views(layout.bindings);
  std::ranges::sort(layout.constants, {}, &ShaderLayout::Constant::id);
  return layout;
}

}  // namespace

ShaderLayout reflect_layout(std::span<const uint32_t> spirv) { return Module(spirv).layout(); }

}  // namespace pbflow::vk
