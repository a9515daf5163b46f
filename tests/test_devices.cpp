// Device listing and selection (lucent::list_devices, select_device, `lucent devices`, --device,
// LUCENT_DEVICE), checked against an independent enumeration through the OpenCL C API.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "cl/opencl.hpp"
#include "lucent/session.hpp"
#include "support.hpp"

namespace test_devices {

namespace {

struct RawDevice {
  std::string platform, name, type, opencl_c;
  unsigned compute_units = 0;
  unsigned long long memory = 0;
  bool fp64 = false;
  bool int64_atomics = false;
};

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back()))))
    s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string platform_string(cl_platform_id p, cl_platform_info what) {
  size_t n = 0;
  clGetPlatformInfo(p, what, 0, nullptr, &n);
  std::string s(n, '\0');
  clGetPlatformInfo(p, what, n, s.data(), nullptr);
  return trim(s);
}

std::string device_string(cl_device_id d, cl_device_info what) {
  size_t n = 0;
  clGetDeviceInfo(d, what, 0, nullptr, &n);
  std::string s(n, '\0');
  clGetDeviceInfo(d, what, n, s.data(), nullptr);
  return trim(s);
}

/// Every device of every platform, in platform then device order, via the C API.
std::vector<RawDevice> raw_devices() {
  std::vector<RawDevice> out;
  cl_uint np = 0;
  if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) return out;
  std::vector<cl_platform_id> platforms(np);
  clGetPlatformIDs(np, platforms.data(), nullptr);
  for (cl_platform_id p : platforms) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS || nd == 0) continue;
    std::vector<cl_device_id> devices(nd);
    clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, nd, devices.data(), nullptr);
    for (cl_device_id d : devices) {
      RawDevice r;
      r.platform = platform_string(p, CL_PLATFORM_NAME);
      r.name = device_string(d, CL_DEVICE_NAME);
      cl_device_type t = 0;
      clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof t, &t, nullptr);
      r.type = (t & CL_DEVICE_TYPE_GPU)           ? "GPU"
               : (t & CL_DEVICE_TYPE_CPU)         ? "CPU"
               : (t & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                  : "other";
      r.opencl_c = device_string(d, CL_DEVICE_OPENCL_C_VERSION);
      cl_uint cu = 0;
      clGetDeviceInfo(d, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, nullptr);
      r.compute_units = cu;
      cl_ulong mem = 0;
      clGetDeviceInfo(d, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof mem, &mem, nullptr);
      r.memory = mem;
      const std::string ext = device_string(d, CL_DEVICE_EXTENSIONS);
      r.fp64 = ext.find("cl_khr_fp64") != std::string::npos;
      r.int64_atomics = ext.find("cl_khr_int64_base_atomics") != std::string::npos;
      out.push_back(r);
    }
  }
  return out;
}

/// Sets (or with nullopt, unsets) an environment variable for the scope of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, std::optional<std::string> value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value)
      ::setenv(name, value->c_str(), 1);
    else
      ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(Devices, ListMatchesTheOpenClApi) {
  std::vector<RawDevice> raw = raw_devices();
  ASSERT_FALSE(raw.empty()) << "no OpenCL device: install pocl-opencl-icd";
  std::vector<lucent::DeviceInfo> listed = lucent::list_devices();
  ASSERT_EQ(listed.size(), raw.size());
  for (size_t i = 0; i < raw.size(); ++i) {
    SCOPED_TRACE(raw[i].name);
    EXPECT_EQ(listed[i].index, static_cast<int>(i));
    EXPECT_EQ(listed[i].platform, raw[i].platform);
    EXPECT_EQ(listed[i].name, raw[i].name);
    EXPECT_EQ(listed[i].type, raw[i].type);
    EXPECT_EQ(listed[i].compute_units, raw[i].compute_units);
    EXPECT_EQ(listed[i].global_memory, raw[i].memory);
    EXPECT_EQ(listed[i].opencl_c_version, raw[i].opencl_c);
    EXPECT_EQ(listed[i].fp64, raw[i].fp64);
    EXPECT_EQ(listed[i].int64_atomics, raw[i].int64_atomics);
    EXPECT_GT(listed[i].compute_units, 0u);
    EXPECT_GT(listed[i].global_memory, 0u);
  }
}

TEST(Devices, PoclCpuDeviceIsListed) {
  bool found = false;
  for (const lucent::DeviceInfo& d : lucent::list_devices())
    found = found || (d.platform == "Portable Computing Language" && d.type == "CPU");
  EXPECT_TRUE(found) << "PoCL's CPU device is the project's reference device";
}

TEST(Devices, CliTableHasOneRowPerDevice) {
  std::vector<RawDevice> raw = raw_devices();
  lucent::test::CommandResult r = lucent::test::run_cli("devices");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  std::istringstream in(r.out);
  std::string header;
  std::getline(in, header);
  for (const char* column :
       {"#", "platform", "device", "type", "CUs", "memory", "OpenCL C", "fp64"})
    EXPECT_NE(header.find(column), std::string::npos) << column << " in: " << header;
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) rows.push_back(line);
  ASSERT_EQ(rows.size(), raw.size()) << r.out;
  for (size_t i = 0; i < raw.size(); ++i) {
    const std::string& row = rows[i];
    std::istringstream fields(row);
    int index = -1;
    fields >> index;
    EXPECT_EQ(index, static_cast<int>(i)) << row;
    // the columns in order: platform, name, type, compute units, memory, OpenCL C, fp64
    size_t at = 0;
    char mem[32];
    double gib = double(raw[i].memory) / (1024.0 * 1024 * 1024);
    if (gib >= 1)
      std::snprintf(mem, sizeof mem, "%.1f GiB", gib);
    else
      std::snprintf(mem, sizeof mem, "%.0f MiB", double(raw[i].memory) / (1024.0 * 1024));
    for (const std::string& field :
         {raw[i].platform, raw[i].name, " " + raw[i].type + " ",
          " " + std::to_string(raw[i].compute_units) + " ", std::string(mem), raw[i].opencl_c,
          std::string(raw[i].fp64 ? " yes" : " no")}) {
      size_t p = row.find(field, at);
      EXPECT_NE(p, std::string::npos) << "'" << field << "' after column " << at << " in: " << row;
      if (p != std::string::npos) at = p + field.size() - 1;
    }
  }
}

TEST(Devices, SelectByIndex) {
  std::vector<RawDevice> raw = raw_devices();
  ScopedEnv env("LUCENT_DEVICE", std::nullopt);
  for (size_t i = 0; i < raw.size(); ++i) {
    lucent::DeviceInfo d = lucent::select_device(std::to_string(i));
    EXPECT_EQ(d.index, static_cast<int>(i));
    EXPECT_EQ(d.name, raw[i].name);
  }
  try {
    lucent::select_device(std::to_string(raw.size()));
    FAIL() << "an index past the last device was accepted";
  } catch (const lucent::Error& e) {
    // the error lists the devices there are
    EXPECT_EQ(std::string(e.what()).rfind("--device " + std::to_string(raw.size()) +
                                              ": no device with this index (available: 0 '" +
                                              raw[0].name + "' (",
                                          0),
              0u)
        << e.what();
  }
}

TEST(Devices, SelectByCaseInsensitiveNameSubstring) {
  std::vector<RawDevice> raw = raw_devices();
  ASSERT_FALSE(raw.empty());
  ScopedEnv env("LUCENT_DEVICE", std::nullopt);
  for (size_t i = 0; i < raw.size(); ++i) {
    const std::string& name = raw[i].name;
    // a piece from the middle of the name, with its letters' case swapped
    std::string piece = name.substr(name.size() / 4, std::max<size_t>(1, name.size() / 2));
    for (char& c : piece)
      c = std::isupper(static_cast<unsigned char>(c))
              ? static_cast<char>(std::tolower(static_cast<unsigned char>(c)))
              : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    size_t expected = 0;  // the first device whose name contains the piece
    while (lower(raw[expected].name).find(lower(piece)) == std::string::npos) ++expected;
    lucent::DeviceInfo d = lucent::select_device(piece);
    EXPECT_EQ(d.index, static_cast<int>(expected)) << "selector '" << piece << "'";
  }
  EXPECT_THROW(lucent::select_device("no such device surely"), lucent::Error);
}

TEST(Devices, DefaultIsFirstGpuElseFirstCpu) {
  std::vector<RawDevice> raw = raw_devices();
  ASSERT_FALSE(raw.empty());
  ScopedEnv env("LUCENT_DEVICE", std::nullopt);
  auto first = [&](const char* type) {
    for (size_t i = 0; i < raw.size(); ++i)
      if (raw[i].type == type) return static_cast<int>(i);
    return -1;
  };
  int expected = first("GPU");
  if (expected < 0) expected = first("CPU");
  if (expected < 0) expected = 0;
  EXPECT_EQ(lucent::select_device().index, expected);
  EXPECT_EQ(lucent::select_device("").index, expected);
}

// LUCENT_DEVICE is the command's default (SessionOptions::from_environment), which the library
// itself does not consult: select_device() ignores it, from_environment() reads it, and the CLI
// reports a selector that matches nothing under the variable's name
// (CliErrors.NoMatchingDevice; Devices.CliRenderUsesTheSelectedDevice renders with it).
TEST(Devices, EnvironmentVariableIsTheCommandsDefault) {
  std::vector<RawDevice> raw = raw_devices();
  ASSERT_FALSE(raw.empty());
  const int last = static_cast<int>(raw.size()) - 1;
  int library_default = lucent::select_device().index;
  {
    ScopedEnv env("LUCENT_DEVICE", std::to_string(last));
    EXPECT_EQ(lucent::SessionOptions::from_environment().device, std::to_string(last));
    EXPECT_EQ(lucent::select_device().index, library_default);
  }
  {
    ScopedEnv env("LUCENT_DEVICE", "no such device surely");
    EXPECT_NO_THROW(lucent::select_device());
    EXPECT_NO_THROW(lucent::Renderer(lucent::SessionOptions{}));
    try {
      lucent::Renderer r(lucent::SessionOptions::from_environment());
      FAIL() << "a LUCENT_DEVICE that matches nothing was accepted";
    } catch (const lucent::Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("device 'no such device surely': no device name "
                                            "contains it (available: 0 '" +
                                                raw[0].name + "' (",
                                            0),
                0u)
          << e.what();
    }
  }
  {
    ScopedEnv env("LUCENT_DEVICE", "");  // empty: as if unset
    EXPECT_EQ(lucent::SessionOptions::from_environment().device, "");
  }
}

// Lists of selectors: an empty one, or "all" (which stands alone), is an error naming the list.
TEST(Devices, SelectorListErrors) {
  auto error_of = [](const std::string& list) {
    try {
      lucent::select_devices(list, "--device");
    } catch (const lucent::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("0,,0"), "--device '0,,0': an empty selector in the list");
  EXPECT_EQ(error_of("0,all"),
            "--device '0,all': 'all' selects every device and stands alone, not in a list");
  EXPECT_EQ(error_of("all"), "");
  EXPECT_EQ(lucent::select_devices("0, 0", "--device").size(), 2u);
  // a selector alone is read as a list's items are: spaces around it, 'all' in any case (' 0'
  // matched no name, where '0, 0' was taken)
  EXPECT_EQ(lucent::select_devices(" 0 ", "--device").at(0).index, 0);
  EXPECT_EQ(lucent::select_devices(" ALL", "--device").size(), lucent::list_devices().size());
  EXPECT_EQ(error_of("0,All"),
            "--device '0,All': 'all' selects every device and stands alone, not in a list");
}

// A name selector: a device's whole name picks it, even listed after a device whose name contains
// it (PoCL's "pthread-skylake-avx512-Intel(R) Xeon(R) Processor" before Intel's CPU runtime's
// "Intel(R) Xeon(R) Processor"); else the first name that contains it, in any case.
TEST(Devices, WholeNameWinsOverALongerNameContainingIt) {
  std::vector<lucent::DeviceInfo> d(3);
  d[0].name = "pthread-skylake-avx512-Intel(R) Xeon(R) Processor";
  d[1].name = "Intel(R) Xeon(R) Processor";
  d[2].name = "NVIDIA H100 80GB HBM3";
  using lucent::cl_util::device_by_name;
  EXPECT_EQ(device_by_name(d, "Intel(R) Xeon(R) Processor"), 1);
  EXPECT_EQ(device_by_name(d, "intel(r) xeon(r) processor"), 1);
  EXPECT_EQ(device_by_name(d, "xeon"), 0);
  EXPECT_EQ(device_by_name(d, "PTHREAD"), 0);
  EXPECT_EQ(device_by_name(d, "h100"), 2);
  EXPECT_EQ(device_by_name(d, "amd"), -1);
}

// The render summary names the device used: --device and LUCENT_DEVICE reach the renderer.
TEST(Devices, CliRenderUsesTheSelectedDevice) {
  std::vector<RawDevice> raw = raw_devices();
  ASSERT_FALSE(raw.empty());
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", R"({
    "film": {"width": 4, "height": 4}, "integrator": {"type": "albedo", "spp": 1},
    "materials": {"m": {"type": "diffuse"}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  const int last = static_cast<int>(raw.size()) - 1;
  std::string args = "render '" + dir + "/s.json' -o '" + dir + "/o.pfm'";
  lucent::test::CommandResult r =
      lucent::test::run_cli(args + " --device " + std::to_string(last), "env -u LUCENT_DEVICE");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(" on " + raw[last].name + "\n"), std::string::npos) << r.err;
  r = lucent::test::run_cli(args, "LUCENT_DEVICE='" + lower(raw[last].name) + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(" on " + raw[last].name + "\n"), std::string::npos) << r.err;
}

}  // namespace

}  // namespace test_devices
