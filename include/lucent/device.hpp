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
  bool int64_atomics = false;  ///< cl_khr_int64_base_atomics: 64-bit atom_cmpxchg
};

/// Every OpenCL device of every platform. Throws lucent::Error when there is no platform.
std::vector<DeviceInfo> list_devices();

/// Picks a device: `selector` is an index, or a device's whole name (case-insensitive), or else a
/// case-insensitive substring of the first device name that contains it;
/// empty means the first GPU, else the first CPU device, else the first device. (The CLI takes
/// LUCENT_DEVICE as its default selector: SessionOptions::from_environment.) Throws lucent::Error
/// when nothing matches; its message calls the selector `origin` ("--device 'x': ...").
DeviceInfo select_device(const std::string& selector = "", const std::string& origin = "--device");

/// Several devices: "all" (every device), or a comma-separated list of selectors, each as for
/// select_device ("0,2", "nvidia,pthread"; a device may be listed twice); a single selector gives
/// one device. Throws lucent::Error naming the selector that matches nothing, or an empty one.
std::vector<DeviceInfo> select_devices(const std::string& selectors,
                                       const std::string& origin = "--device");

}  // namespace lucent
