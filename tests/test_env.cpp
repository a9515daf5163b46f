// Environment variables on their error paths: a LUCENT_CACHE_DIR that is a file or cannot be
// created or written falls back to building without the cache, with one warning, and the render
// goes on; cache entries replaced by a pipe or a directory are rebuilt without hanging. (Devices:
// test_cli_errors.cpp, NoMatchingDevice; LUCENT_KERNEL_DIR: test_kernel_source.cpp.)
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "support.hpp"

namespace test_env {

namespace {

namespace fs = std::filesystem;
using lucent::test::CommandResult;
using lucent::test::run_cli;

std::string q(const std::string& s) { return "'" + s + "'"; }

std::string small_scene() {
  std::string path = lucent::test::temp_dir() + "/scene.json";
  lucent::test::write_file(path, R"({"film": {"width": 8, "height": 8},
    "integrator": {"type": "albedo", "spp": 1},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  return path;
}

// (With PoCL's own cache off: where the driver caches its builds, lucent's directory is unused.)
// On PoCL, whose sessions keep no entries in lucent's cache (keeps_program_binaries), the
// directory holds build locks only, and one that cannot serve goes unsaid: the render is the same.
TEST(Env, UnusableCacheDirWarnsAndRenders) {
  const bool entries = lucent::cl_util::keeps_program_binaries(
      lucent::cl_util::Context(lucent::test::device()).device);
  std::string dir = lucent::test::temp_dir();
  std::string file = dir + "/a-file";
  lucent::test::write_file(file, "x");
  struct Case {
    std::string value, warning;
  } cases[] = {
      {file, "lucent: warning: kernel cache " + file +
                 ": not a directory; kernels are built without the cache\n"},
      {file + "/sub", "lucent: warning: kernel cache " + file +
                          "/sub: Not a directory; kernels are built without the cache\n"},
  };
  for (const Case& c : cases) {
    std::string out = dir + "/o.pfm";
    CommandResult r = run_cli("render " + q(small_scene()) + " -o " + q(out) + " --quiet",
                              "POCL_KERNEL_CACHE=0 LUCENT_CACHE_DIR=" + q(c.value));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, entries ? c.warning : "");
    EXPECT_EQ(lucent::read_image(out).width, 8);
    fs::remove(out);
  }
  if (::geteuid() != 0) {  // root writes anywhere
    std::string ro = dir + "/ro";
    fs::create_directories(ro);
    ::chmod(ro.c_str(), 0555);
    CommandResult r =
        run_cli("render " + q(small_scene()) + " -o " + q(dir + "/o.pfm") + " --quiet",
                "POCL_KERNEL_CACHE=0 LUCENT_CACHE_DIR=" + q(ro));
    ::chmod(ro.c_str(), 0755);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, entries ? "lucent: warning: kernel cache " + ro +
                                   ": Permission denied; kernels are built without the cache\n"
                             : "");
  }
}

// An entry replaced by a FIFO (a read would block forever) or by a directory: rebuilt, with a
// note naming the entry; the directory cannot be replaced, which is one warning.
TEST(Env, CacheEntriesThatAreNotFilesAreRebuilt) {
  std::string dir = lucent::test::temp_dir() + "/cache";
  lucent::cl_util::Context ctx("");
  std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  lucent::cl_util::ProgramBuildInfo a, b, c, d;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_ENV_TEST", dir, &a);
  ASSERT_TRUE(fs::is_regular_file(a.cache_file));
  fs::remove(a.cache_file);
  ASSERT_EQ(::mkfifo(a.cache_file.c_str(), 0600), 0);
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_ENV_TEST", dir, &b);
  EXPECT_FALSE(b.cache_hit);
  EXPECT_EQ(b.note,
            a.cache_file + ": is a pipe, not a cache entry (only regular files are read); rebuilt");
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_ENV_TEST", dir, &c);
  EXPECT_TRUE(c.cache_hit) << "the rebuilt entry replaced the pipe";

  fs::remove(a.cache_file);
  fs::create_directories(a.cache_file + "/inside");
  lucent::test::CaptureWarnings warnings;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_ENV_TEST", dir, &d);
  EXPECT_FALSE(d.cache_hit);
  EXPECT_EQ(d.note, a.cache_file + ": is a directory, not a cache entry; rebuilt");
  EXPECT_EQ(warnings.count(a.cache_file + ": cannot write (Is a directory); the kernel cache is "
                                          "not updated"),
            1)
      << warnings.dump();
  EXPECT_TRUE(fs::is_directory(a.cache_file + "/inside"));
}

}  // namespace

}  // namespace test_env
