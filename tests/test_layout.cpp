// The device sees the shared structs (kernels/shared/types.h) exactly as the host does.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "probe_launch.hpp"
#include "shared/types.h"
#include "support.hpp"

namespace test_layout {

namespace {

struct Entry {
  std::string what;
  lc_uint host;
};

std::vector<Entry> host_entries() {
  std::vector<Entry> e;
#define LUCENT_LAYOUT_SIZE(t) e.push_back({"sizeof(" #t ")", (lc_uint)sizeof(t)});
#define LUCENT_LAYOUT_ALIGN(t) e.push_back({"alignof(" #t ")", (lc_uint)alignof(t)});
#define LUCENT_LAYOUT_OFFSET(t, m) \
  e.push_back({"offsetof(" #t ", " #m ")", (lc_uint)LC_OFFSETOF(t, m)});
#include "shared/layout_entries.h"
#undef LUCENT_LAYOUT_SIZE
#undef LUCENT_LAYOUT_ALIGN
#undef LUCENT_LAYOUT_OFFSET
  return e;
}

TEST(Layout, DeviceSeesTheHostLayout) {
  auto entries = host_entries();
  lucent::cl_util::Context ctx{lucent::test::device()};
  cl::Program program = lucent::cl_util::build_program(
      ctx,
      lucent::detail::assemble_kernel_source("test/layout_probe.cl", lucent::test::kernel_dir()),
      "-cl-std=CL1.2");
  cl::Kernel k(program, "lucent_layout_probe");
  cl::Buffer out(ctx.context, CL_MEM_WRITE_ONLY, entries.size() * sizeof(lc_uint));
  k.setArg(0, out);
  ctx.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NullRange);
  std::vector<lc_uint> device = lucent::test::read_back<lc_uint>(ctx.queue, out, entries.size());
  for (size_t i = 0; i < entries.size(); ++i)
    EXPECT_EQ(device[i], entries[i].host)
        << entries[i].what << " differs on " << ctx.device.info.name;
}

// Buffer elements are 16-byte aligned multiples of 16; the per-type parameter structs and their
// unions (lc_*_params, members of lc_material and lc_light) are exempt.
TEST(Layout, StructsAre16ByteAlignedMultiplesOf16) {
  for (const auto& e : host_entries()) {
    if (e.what.find("_params)") != std::string::npos) continue;
    if (e.what.rfind("sizeof", 0) == 0) {
      EXPECT_EQ(e.host % 16, 0u) << e.what;
    }
    if (e.what.rfind("alignof", 0) == 0) {
      EXPECT_EQ(e.host, 16u) << e.what;
    }
  }
}

// Every field declared in types.h is in the probe list, so the device test covers it.
TEST(Layout, ProbeListCoversEveryField) {
  std::ifstream f(std::string(LUCENT_SOURCE_DIR) + "/kernels/shared/types.h");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string src = ss.str();
  std::set<std::string> listed;
  for (const auto& e : host_entries()) listed.insert(e.what);
  std::regex st(R"(typedef struct LC_ALIGN16 (\w+) \{([^}]*)\} \1;)");
  std::regex field(R"((?:float|lc_uint|lc_int|lc_camera)\s+([^;]+);)");
  int structs = 0;
  for (auto it = std::sregex_iterator(src.begin(), src.end(), st); it != std::sregex_iterator();
       ++it) {
    ++structs;
    std::string name = (*it)[1], body = (*it)[2];
    EXPECT_TRUE(listed.count("sizeof(" + name + ")")) << name;
    for (auto f2 = std::sregex_iterator(body.begin(), body.end(), field);
         f2 != std::sregex_iterator(); ++f2) {
      std::string decl = (*f2)[1];
      std::stringstream parts(decl);
      std::string one;
      while (std::getline(parts, one, ',')) {
        one.erase(0, one.find_first_not_of(' '));
        one = one.substr(0, one.find('['));
        one = one.substr(0, one.find(' '));
        EXPECT_TRUE(listed.count("offsetof(" + name + ", " + one + ")")) << name << "." << one;
      }
    }
  }
  EXPECT_GE(structs, 9);
}

}  // namespace

}  // namespace test_layout
