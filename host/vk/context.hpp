#pragma once
// The Vulkan instance, the chosen device and its compute queue. One per process;
// every other Vulkan object borrows it and must be destroyed before it.
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace pbflow::vk {

class ProgramCache;

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  std::string kind;  // "discrete", "integrated", "virtual", "cpu", "other"
  uint32_t api_version = 0;
  std::string driver;   // the driver's name and version as it states them ("llvmpipe, Mesa 22.3.6")
  uint64_t device_local_bytes = 0;
  uint32_t max_workgroup_invocations = 0;
  uint64_t max_storage_buffer_range = 0;
  uint64_t max_texel_buffer_elements = 0;
  bool timestamps = false;
  bool usable = false;  // has a compute queue and the extensions pbflow needs
};

class Context {
 public:
  struct Options {
    std::string device = "auto";  // "auto" or a device index
    bool validate = false;        // enable VK_LAYER_KHRONOS_validation
    uint32_t workgroup_size = 0;  // 0: chosen for the device
    // Keep every program made, for a process that makes the same ones again (the tests): a
    // program made alike shares its pipeline (vk/program_cache.hpp).
    bool keep_programs = false;
  };

  explicit Context(const Options& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  // All Vulkan devices, in the order --device INDEX counts them.
  static std::vector<DeviceInfo> list_devices();

  VkDevice device() const { return device_; }
  VkPhysicalDevice physical() const { return physical_; }
  VkQueue queue() const { return queue_; }
  VkCommandPool command_pool() const { return pool_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceLimits& limits() const { return limits_; }
  uint32_t workgroup_size() const { return workgroup_size_; }
  bool validating() const { return validate_; }
  ProgramCache* kept_programs() const { return programs_.get(); }  // null where none are kept

  uint32_t memory_type(uint32_t type_bits, VkMemoryPropertyFlags wanted) const;
  PFN_vkCmdPushDescriptorSetKHR push_descriptor_set = nullptr;

  // Memory export for the renderer (VK_KHR_external_memory_fd, optional); GL matches
  // its device by this UUID before it imports anything.
  bool external_memory_fd() const { return external_memory_fd_ && get_memory_fd; }
  PFN_vkGetMemoryFdKHR get_memory_fd = nullptr;
  const std::array<uint8_t, VK_UUID_SIZE>& device_uuid() const { return device_uuid_; }

  // Records commands into a one-time command buffer, submits them and waits.
  void submit_and_wait(const std::function<void(VkCommandBuffer)>& record) const;

  // Bytes of the vk::Buffers alive in this context, as requested (each allocation rounds
  // them up to the device's alignment); the memory estimate's test holds the plan to it.
  uint64_t buffer_bytes() const { return buffer_bytes_; }
  void count_buffer_bytes(int64_t delta) const { buffer_bytes_ += uint64_t(delta); }

  // Validation messages (warnings and errors) seen so far; tests require none.
  std::vector<std::string> validation_messages() const;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT*,
                                                   void*);

  void create_messenger();
  void create_device();
  void release() noexcept;

  bool validate_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::unique_ptr<ProgramCache> programs_;  // where Options::keep_programs
  DeviceInfo info_;
  VkPhysicalDeviceLimits limits_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  uint32_t workgroup_size_ = 64;
  bool external_memory_fd_ = false;
  std::array<uint8_t, VK_UUID_SIZE> device_uuid_{};
  mutable std::atomic<uint64_t> buffer_bytes_{0};
  mutable std::mutex messages_mutex_;
  std::vector<std::string> messages_;
};

// Makes all earlier compute, transfer and host writes visible to later commands and the host.
void memory_barrier(VkCommandBuffer cb);

}  // namespace pbflow::vk
