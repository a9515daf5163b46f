#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace lucent {

struct DeviceInfo {
  int index = 0;  ///< global index over all platforms, as `lucent devices` prints it
  std::string platform;
  std::string name;
  std::string type;  ///< "GPU", "CPU", "accelerator", "other"
  std::string vendor;
  std::string driver_version;
  std::string opencl_c_version;
  unsigned compute_units = 0;
  std::uint64_t global_memory = 0;  ///< bytes
  bool fp64 = false;
};

/// Every OpenCL device of every platform. Throws lucent::Error when there is no platform.
std::vector<DeviceInfo> list_devices();

/// Picks a device: `selector` is an index or a case-insensitive substring of the device name;
/// empty means LUCENT_DEVICE if set, else the first GPU, else the first CPU device, else the
/// first device. Throws lucent::Error when nothing matches.
DeviceInfo select_device(const std::string& selector = "");

}  // namespace lucent
