#pragma once
// SPIR-V of the compute shaders, compiled by glslc at build time (cmake/embed.cmake).
#include <cstdint>
#include <span>
#include <string_view>

namespace pbflow::shaders {
// Words of the shader compiled from shaders/<name>.comp; throws if there is none.
std::span<const uint32_t> spirv(std::string_view name);
}  // namespace pbflow::shaders
