#pragma once
// Every VkResult is checked: a failure throws with the call that failed and where.
#include <vulkan/vulkan.h>

#include <source_location>
#include <stdexcept>
#include <string>

namespace pbflow::vk {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// --device names no usable device: bad input rather than a failure of the run.
struct DeviceSelectionError : Error {
  using Error::Error;
};

const char* result_name(VkResult r);

inline void check(VkResult r, const char* what,
                  std::source_location at = std::source_location::current()) {
  if (r != VK_SUCCESS)
    throw Error(std::string(what) + " failed with " + result_name(r) + " (" + at.file_name() +
                ":" + std::to_string(at.line()) + ")");
}

}  // namespace pbflow::vk

// VK_CHECK(vkCreateBuffer(...)) names the call in the error message.
#define VK_CHECK(call) ::pbflow::vk::check((call), #call)
