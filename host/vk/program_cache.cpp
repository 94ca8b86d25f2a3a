#include "vk/program_cache.hpp"

#include <utility>

namespace pbflow::vk {

CompiledProgram::~CompiledProgram() {
  if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
}

std::shared_ptr<const CompiledProgram> ProgramCache::find(const std::string& key) const {
  std::lock_guard lock(mutex_);
  auto k = kept_.find(key);
  return k == kept_.end() ? nullptr : k->second;
}

void ProgramCache::keep(const std::string& key, std::shared_ptr<const CompiledProgram> compiled) {
  std::lock_guard lock(mutex_);
  kept_.emplace(key, std::move(compiled));
}

}  // namespace pbflow::vk
