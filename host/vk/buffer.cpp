#include "vk/buffer.hpp"

#include <sys/resource.h>

#include <string>

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace pbflow::vk {

Buffer::Buffer(const Context& ctx, VkDeviceSize bytes, Memory memory) : ctx_(&ctx), bytes_(bytes) {
  if (bytes == 0) bytes = 4;  // Vulkan forbids empty buffers; an empty scene still binds something
  if (bytes > ctx.limits().maxStorageBufferRange)
    throw Error("a buffer of " + std::to_string(bytes) + " bytes exceeds the device's storage buffer limit of " +
                std::to_string(ctx.limits().maxStorageBufferRange) + " bytes (fewer particles needed)");
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT |
               VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkExternalMemoryBufferCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  if (memory == Memory::Shared) {
    if (!ctx.external_memory_fd()) throw Error("this Vulkan device cannot export memory (VK_KHR_external_memory_fd)");
    info.pNext = &external;
  }
  VK_CHECK(vkCreateBuffer(ctx.device(), &info, nullptr, &buffer_));
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
    VkExportMemoryAllocateInfo export_info{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO};
    export_info.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    if (memory == Memory::Shared) alloc.pNext = &export_info;
    alloc.allocationSize = allocation_bytes_ = req.size;
    alloc.memoryTypeIndex = ctx.memory_type(
        req.memoryTypeBits, memory == Memory::Host
                                ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    const VkResult allocated = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
    // Memory exported as a file descriptor is a file to the kernel (lavapipe's is a memfd):
    // past a file-size limit it cannot be sized, and the driver reports that as out of memory.
    rlimit file_size{};
    if (allocated != VK_SUCCESS && memory == Memory::Shared && getrlimit(RLIMIT_FSIZE, &file_size) == 0 &&
        file_size.rlim_cur != RLIM_INFINITY && file_size.rlim_cur < req.size)
      throw Error("cannot share " + std::to_string((req.size + 1023) >> 10) + " KiB between the solver and the renderer: a "
                  "file-size limit of " + std::to_string(file_size.rlim_cur >> 10) + " KiB is in force (ulimit -f), and " +
                  ctx.info().name + " keeps shared memory in a file; raise the limit");
    VK_CHECK(allocated);
    VK_CHECK(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0));
    if (memory == Memory::Host) VK_CHECK(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    ctx.count_buffer_bytes(int64_t(bytes_));
  } catch (...) {
    release();
    throw;
  }
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = std::exchange(o.ctx_, nullptr);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    bytes_ = std::exchange(o.bytes_, 0);
    allocation_bytes_ = std::exchange(o.allocation_bytes_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
    views_ = std::exchange(o.views_, {});
  }
  return *this;
}

void Buffer::release() noexcept {
  if (!ctx_) return;
  for (View& v : views_)
    if (v.view) vkDestroyBufferView(ctx_->device(), v.view, nullptr);
  views_ = {};
  if (buffer_) vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
  if (memory_) {
    vkFreeMemory(ctx_->device(), memory_, nullptr);  // unmaps too
    ctx_->count_buffer_bytes(-int64_t(bytes_));
  }
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

int Buffer::export_fd() const {
  if (!ctx_ || !ctx_->external_memory_fd()) throw Error("export_fd: the buffer's memory cannot be exported");
  VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
  info.memory = memory_;
  info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  VK_CHECK(ctx_->get_memory_fd(ctx_->device(), &info, &fd));
  return fd;
}

namespace {
// The bytes of one texel in the formats the passes read through texel buffers.
VkDeviceSize texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
      return 4;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT:
      return 16;
    default:
      throw Error("a texel buffer view in a format the passes do not read (" + std::to_string(format) + ")");
  }
}
}  // namespace

VkBufferView Buffer::view(VkFormat format) const {
  for (const View& v : views_)
    if (v.format == format) return v.view;
  for (View& v : views_) {
    if (v.view) continue;
    const VkDeviceSize texel = texel_bytes(format);
    if (bytes_ / texel > ctx_->limits().maxTexelBufferElements)
      throw Error("a texel buffer of " + std::to_string(bytes_ / texel) + " elements exceeds the device's limit of " +
                  std::to_string(ctx_->limits().maxTexelBufferElements) + " (fewer particles needed)");
    VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    info.buffer = buffer_;
    info.format = format;
    info.range = VK_WHOLE_SIZE;
    VK_CHECK(vkCreateBufferView(ctx_->device(), &info, nullptr, &v.view));
    v.format = format;
    return v.view;
  }
  throw Error("a buffer was asked for a view in a fourth format");
}

void Buffer::upload(const void* data, VkDeviceSize bytes) {
  if (bytes > bytes_) throw Error("upload of " + std::to_string(bytes) + " bytes into a smaller buffer");
  if (bytes == 0) return;
  Buffer staging(*ctx_, bytes, Memory::Host);
  std::memcpy(staging.mapped(), data, bytes);
  ctx_->submit_and_wait([&](VkCommandBuffer cb) {
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cb, staging.handle(), buffer_, 1, &region);
    memory_barrier(cb);  // the copy is visible to the shaders of later submissions
  });
}

void Buffer::download(void* data, VkDeviceSize bytes) const {
  if (bytes > bytes_) throw Error("download of " + std::to_string(bytes) + " bytes from a smaller buffer");
  if (bytes == 0) return;
  Buffer staging(*ctx_, bytes, Memory::Host);
  ctx_->submit_and_wait([&](VkCommandBuffer cb) {
    memory_barrier(cb);  // earlier shader writes are visible to the copy
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cb, buffer_, staging.handle(), 1, &region);
    memory_barrier(cb);  // and the copy to the host
  });
  std::memcpy(data, staging.mapped(), bytes);
}

}  // namespace pbflow::vk
