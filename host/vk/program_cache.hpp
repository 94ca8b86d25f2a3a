#pragma once
// The programs a context keeps where asked (Context::Options::keep_programs): each program's
// Vulkan objects made once per shader, push block and constants, for a process that makes the
// same programs again and again. A pass test's GpuSolver makes ~35 pipelines, most of the test's
// time on lavapipe (2.1 s a test, 0.17 s with its programs kept); a run makes each once.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace pbflow::vk {

// A program's descriptor set layout, pipeline layout and pipeline, destroyed with the last owner.
struct CompiledProgram {
  VkDevice device = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  explicit CompiledProgram(VkDevice d) : device(d) {}
  ~CompiledProgram();
  CompiledProgram(const CompiledProgram&) = delete;
  CompiledProgram& operator=(const CompiledProgram&) = delete;
};

class ProgramCache {
 public:
  // The objects kept under `key` (what they were made from), or null.
  std::shared_ptr<const CompiledProgram> find(const std::string& key) const;
  void keep(const std::string& key, std::shared_ptr<const CompiledProgram> compiled);

 private:
  mutable std::mutex mutex_;
  std::unordered_map<std::string, std::shared_ptr<const CompiledProgram>> kept_;
};

}  // namespace pbflow::vk
