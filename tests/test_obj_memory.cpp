// The host memory of loading a large OBJ file (src/scene/obj.cpp): its peak, measured in a child
// process, against what the loader's up-front check counts (obj::mesh_load_bytes). The text was
// held whole beside tinyobjloader's arrays and the scene's, and tinyobjloader's arrays beside the
// scene's: a 10^6-triangle soup took 344 MiB at its peak where the check counted 274 (and the
// scene keeps 107).
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "lucent/scene.hpp"
#include "scene/obj_internal.hpp"
#include "support.hpp"

namespace test_obj_memory {

namespace {

/// The peak resident memory that load_scene(`scene`) adds, in bytes, measured in a child process,
/// or -1 when it cannot be measured.
double load_peak_bytes(const std::string& scene) {
  return lucent::test::child_peak_bytes([&] { return !lucent::load_scene(scene).path.empty(); });
}

}  // namespace

// A soup of 200,000 separate triangles (20 MB of text): the load's peak stays within what
// check_mesh_memory counts for it, which is not a wide overestimate. It took 1.4 times the count
// (the text held while tinyobjloader read it and while the scene's arrays were filled,
// tinyobjloader's arrays beside the scene's, and its faces' small arrays kept by glibc).
TEST(ObjMemory, PeakOfALargeMeshIsWithinTheLoadersCount) {
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's memory is in the peak";
  const std::string dir = lucent::test::temp_dir();
  const int n = 200000;
  std::string obj = lucent::test::soup_obj_text(n);
  lucent::test::write_file(dir + "/soup.obj", obj);
  lucent::test::write_file(dir + "/soup.json",
                           R"({"camera": {"position": [5, 5, -20], "look_at": [5, 5, 5]},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "mesh", "file": "soup.obj", "material": "m"}]})");
  namespace obj_ns = lucent::scene_detail::obj;
  const obj_ns::TextCounts counts = obj_ns::check_obj_text(dir + "/soup.obj", obj);
  const double count = double(obj_ns::mesh_load_bytes(lucent::Scene{}, obj.size(), counts).need);
  std::string().swap(obj);

  const double peak = load_peak_bytes(dir + "/soup.json");
  ASSERT_GT(peak, 0) << "the child process could not measure its peak";
  const double mib = 1048576.0;
  EXPECT_LE(peak, count) << "peak " << peak / mib << " MiB, counted " << count / mib << " MiB";
  EXPECT_GE(peak, 0.6 * count) << "peak " << peak / mib << " MiB, counted " << count / mib
                               << " MiB";
}

}  // namespace test_obj_memory
