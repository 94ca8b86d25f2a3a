#pragma once
// A storage buffer and its memory: move-only, freed with the object.
#include <vulkan/vulkan.h>

#include <array>
#include <cstring>
#include <span>
#include <utility>
#include <vector>

namespace pbflow::vk {

class Context;

enum class Memory {
  Device,  // device-local; filled and read through staging copies
  Host,    // host-visible and coherent, mapped for its whole life (readback of small results)
  Shared,  // device-local and exportable as an opaque fd (Context::external_memory_fd)
};

class Buffer {
 public:
  Buffer() = default;
  Buffer(const Context& ctx, VkDeviceSize bytes, Memory memory = Memory::Device);
  ~Buffer() { release(); }
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize bytes() const { return bytes_; }
  void* mapped() const { return mapped_; }  // Memory::Host only
  VkDeviceSize allocation_bytes() const { return allocation_bytes_; }
  // A new fd for the memory (Memory::Shared only); whoever imports it owns it.
  int export_fd() const;
  // The buffer read as a storage texel buffer of `format` (made on first use, kept with
  // the buffer): a pass's gathers go through the image path (see vk/program.hpp).
  VkBufferView view(VkFormat format) const;

  // Whole-buffer transfers through a staging buffer (one submit each); tests and set-up only.
  void upload(const void* data, VkDeviceSize bytes);
  void download(void* data, VkDeviceSize bytes) const;

  template <class T>
  void upload(std::span<const T> items) { upload(items.data(), items.size_bytes()); }
  template <class T>
  std::vector<T> download(size_t count) const {
    std::vector<T> items(count);
    download(items.data(), count * sizeof(T));
    return items;
  }

 private:
  void release() noexcept;

  const Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize bytes_ = 0, allocation_bytes_ = 0;
  void* mapped_ = nullptr;
  struct View {
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkBufferView view = VK_NULL_HANDLE;
  };
  mutable std::array<View, 3> views_{};  // a buffer is read in at most three formats
};

}  // namespace pbflow::vk
