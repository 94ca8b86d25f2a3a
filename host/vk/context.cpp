#include "vk/context.hpp"

#include <algorithm>
#include <cstring>
#include <iostream>

#include "vk/check.hpp"
#include "vk/program_cache.hpp"

namespace pbflow::vk {

const char* result_name(VkResult r) {
  switch (r) {
#define PBFLOW_RESULT(name) \
  case name:                \
    return #name;
    PBFLOW_RESULT(VK_NOT_READY)
    PBFLOW_RESULT(VK_TIMEOUT)
    PBFLOW_RESULT(VK_INCOMPLETE)
    PBFLOW_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    PBFLOW_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    PBFLOW_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    PBFLOW_RESULT(VK_ERROR_DEVICE_LOST)
    PBFLOW_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    PBFLOW_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    PBFLOW_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    PBFLOW_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    PBFLOW_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    PBFLOW_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    PBFLOW_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    PBFLOW_RESULT(VK_ERROR_UNKNOWN)
#undef PBFLOW_RESULT
    default:
      return "VkResult error";
  }
}

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kRequiredDeviceExtensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

const char* kind_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

// "auto" prefers real GPUs, then software rasterisers: lower rank wins.
int auto_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

bool has_layer(const char* name) {
  uint32_t n = 0;
  VK_CHECK(vkEnumerateInstanceLayerProperties(&n, nullptr));
  std::vector<VkLayerProperties> layers(n);
  VK_CHECK(vkEnumerateInstanceLayerProperties(&n, layers.data()));
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

VkInstance create_instance(bool validate) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "pbflow";
  app.apiVersion = VK_API_VERSION_1_2;
  std::vector<const char*> layers, extensions;
  if (validate) {
    if (!has_layer(kValidationLayer))
      throw Error(std::string("validation requested but ") + kValidationLayer +
                  " is not installed (Debian package vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&info, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw Error("no Vulkan driver found (install mesa-vulkan-drivers for lavapipe, or a GPU driver)");
  VK_CHECK(r);
  return instance;
}

std::vector<VkPhysicalDevice> physical_devices(VkInstance instance) {
  uint32_t n = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> devices(n);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, devices.data()));
  return devices;
}

int compute_queue_family(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  for (uint32_t i = 0; i < n; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return int(i);
  return -1;
}

bool has_extension(VkPhysicalDevice pd, const char* want) {
  uint32_t n = 0;
  VK_CHECK(vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr));
  std::vector<VkExtensionProperties> ext(n);
  VK_CHECK(vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, ext.data()));
  return std::any_of(ext.begin(), ext.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, want) == 0; });
}

bool has_extensions(VkPhysicalDevice pd) {
  return std::all_of(std::begin(kRequiredDeviceExtensions), std::end(kRequiredDeviceExtensions),
                     [&](const char* want) { return has_extension(pd, want); });
}

DeviceInfo describe(VkPhysicalDevice pd, uint32_t index) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(pd, &p);
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(pd, &mem);
  DeviceInfo d;
  d.index = index;
  d.name = p.deviceName;
  d.kind = kind_name(p.deviceType);
  d.api_version = p.apiVersion;
  if (p.apiVersion >= VK_API_VERSION_1_2) {  // Vulkan 1.2's driver properties: what a result is reproducible against
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
    vkGetPhysicalDeviceProperties2(pd, &p2);
    d.driver = std::string(driver.driverName) + ", " + driver.driverInfo;
  }
  for (uint32_t i = 0; i < mem.memoryHeapCount; ++i)
    if (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      d.device_local_bytes = std::max<uint64_t>(d.device_local_bytes, mem.memoryHeaps[i].size);
  d.max_workgroup_invocations = p.limits.maxComputeWorkGroupInvocations;
  d.max_storage_buffer_range = p.limits.maxStorageBufferRange;
  d.max_texel_buffer_elements = p.limits.maxTexelBufferElements;
  int family = compute_queue_family(pd);
  if (family >= 0) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
    d.timestamps = p.limits.timestampPeriod > 0 && families[family].timestampValidBits > 0;
  }
  d.usable = family >= 0 && has_extensions(pd);
  return d;
}

// Workgroup size per device kind: a multiple of the SIMD width that keeps enough
// work in flight (NVIDIA warps of 32, AMD waves of 64; lavapipe runs a workgroup
// on one CPU thread in 8-wide lanes, where larger groups mean less dispatch overhead).
uint32_t preferred_workgroup_size(const VkPhysicalDeviceProperties& p) {
  uint32_t size = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 128 : p.vendorID == 0x1002 ? 256 : 128;
  return std::min(size, p.limits.maxComputeWorkGroupInvocations);
}

// The device `--device` names: "auto" the usable one of the best kind (auto_rank), or an index.
uint32_t choose_device(const std::vector<VkPhysicalDevice>& devices, const std::string& option) {
  if (option == "auto") {
    int chosen = -1, best_rank = 1 << 30;
    for (uint32_t i = 0; i < devices.size(); ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(devices[i], &p);
      if (describe(devices[i], i).usable && auto_rank(p.deviceType) < best_rank) {
        best_rank = auto_rank(p.deviceType);
        chosen = int(i);
      }
    }
    if (chosen < 0) throw Error("no Vulkan device has a compute queue and VK_KHR_push_descriptor");
    return uint32_t(chosen);
  }
  size_t used = 0;
  unsigned long index = 0;
  try {
    index = std::stoul(option, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != option.size())
    throw DeviceSelectionError("--device must be auto, cpu or a device index, not '" + option + "'");
  if (index >= devices.size())
    throw DeviceSelectionError("--device " + option + ": there are only " + std::to_string(devices.size()) +
                               " Vulkan devices (see 'pbflow devices')");
  if (!describe(devices[index], uint32_t(index)).usable)
    throw DeviceSelectionError("Vulkan device " + option + " lacks a compute queue or VK_KHR_push_descriptor");
  return uint32_t(index);
}

}  // namespace

std::vector<DeviceInfo> Context::list_devices() {
  VkInstance instance = create_instance(false);
  std::vector<DeviceInfo> out;
  auto devices = physical_devices(instance);
  for (uint32_t i = 0; i < devices.size(); ++i) out.push_back(describe(devices[i], i));
  vkDestroyInstance(instance, nullptr);
  return out;
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
  auto* self = static_cast<Context*>(user);
  std::lock_guard lock(self->messages_mutex_);
  self->messages_.emplace_back(data->pMessage ? data->pMessage : "(no message)");
  std::cerr << "pbflow: Vulkan validation: " << self->messages_.back() << "\n";
  return VK_FALSE;
}

Context::Context(const Options& options) : validate_(options.validate) {
  instance_ = create_instance(validate_);
  try {
    if (validate_) create_messenger();
    const std::vector<VkPhysicalDevice> devices = physical_devices(instance_);
    if (devices.empty()) throw Error("no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
    const uint32_t chosen = choose_device(devices, options.device);
    physical_ = devices[chosen];
    info_ = describe(physical_, chosen);
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical_, &props);
    limits_ = props.limits;
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
    workgroup_size_ = options.workgroup_size ? options.workgroup_size : preferred_workgroup_size(props);
    if (workgroup_size_ > limits_.maxComputeWorkGroupInvocations)
      throw Error("workgroup size " + std::to_string(workgroup_size_) + " exceeds the device limit of " +
                  std::to_string(limits_.maxComputeWorkGroupInvocations));
    create_device();
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queue_family_;
    VK_CHECK(vkCreateCommandPool(device_, &pool, nullptr, &pool_));
    if (options.keep_programs) programs_ = std::make_unique<ProgramCache>();
  } catch (...) {
    release();
    throw;
  }
}

// Validation messages (warnings and errors) reach on_message, which records them.
void Context::create_messenger() {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  info.pfnUserCallback = &Context::on_message;
  info.pUserData = this;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
  if (!create) throw Error("vkCreateDebugUtilsMessengerEXT is not available");
  VK_CHECK(create(instance_, &info, nullptr, &messenger_));
}

// The logical device on physical_'s compute queue, with the extensions pbflow needs and
// external memory where the device has it, and the entry points and UUID it is used through.
void Context::create_device() {
  queue_family_ = uint32_t(compute_queue_family(physical_));
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  // Optional: exporting memory lets the renderer read solver buffers without a host copy.
  std::vector<const char*> extensions(std::begin(kRequiredDeviceExtensions), std::end(kRequiredDeviceExtensions));
  external_memory_fd_ = has_extension(physical_, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
  if (external_memory_fd_) extensions.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(vkCreateDevice(physical_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  push_descriptor_set =
      reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
  if (!push_descriptor_set) throw Error("vkCmdPushDescriptorSetKHR is not available");
  if (external_memory_fd_)
    get_memory_fd = reinterpret_cast<PFN_vkGetMemoryFdKHR>(vkGetDeviceProcAddr(device_, "vkGetMemoryFdKHR"));
  VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &id};
  vkGetPhysicalDeviceProperties2(physical_, &props2);
  std::copy(std::begin(id.deviceUUID), std::end(id.deviceUUID), device_uuid_.begin());
}

Context::~Context() { release(); }

void Context::release() noexcept {
  if (device_) {
    vkDeviceWaitIdle(device_);
    programs_.reset();  // the kept programs' pipelines, before their device
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  device_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

uint32_t Context::memory_type(uint32_t type_bits, VkMemoryPropertyFlags wanted) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  throw Error("no Vulkan memory type with the properties a buffer needs");
}

void Context::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) const {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  VK_CHECK(vkAllocateCommandBuffers(device_, &alloc, &cb));
  try {
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cb, &begin));
    record(cb);
    VK_CHECK(vkEndCommandBuffer(cb));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    VK_CHECK(vkQueueSubmit(queue_, 1, &submit, VK_NULL_HANDLE));
    VK_CHECK(vkQueueWaitIdle(queue_));
  } catch (...) {
    vkFreeCommandBuffers(device_, pool_, 1, &cb);
    throw;
  }
  vkFreeCommandBuffers(device_, pool_, 1, &cb);
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard lock(messages_mutex_);
  return messages_;
}

void memory_barrier(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                          VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  constexpr VkPipelineStageFlags src =
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT;
  constexpr VkPipelineStageFlags dst = src | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;  // indirect dispatch arguments
  vkCmdPipelineBarrier(cb, src, dst, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace pbflow::vk
