#pragma once
// Whether a device is PoCL's, from its DeviceInfo alone: without the OpenCL headers, whose
// wrappers' destructors call the OpenCL library (render/features.cpp asks it for its device
// defines, and the fuzz targets link that file without OpenCL).
#include <string>

#include "lucent/device.hpp"

namespace lucent::cl_util {

/// PoCL's platform name (CL_PLATFORM_NAME).
inline constexpr const char* kPoclPlatform = "Portable Computing Language";

/// The device is PoCL's (any of its drivers: they share its kernel cache and POCL_* variables).
inline bool is_pocl(const DeviceInfo& device) {
  return device.platform.find(kPoclPlatform) != std::string::npos;
}

}  // namespace lucent::cl_util
