// Kernel sources: embedded in the binary (the CLI works from any directory), loaded from
// LUCENT_KERNEL_DIR when set, and a build failure shows the log with kernels/<file>:<line>.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "lucent/session.hpp"
#include "render/features.hpp"
#include "support.hpp"

namespace test_kernel_source {

namespace {

namespace fs = std::filesystem;
using lucent::test::CommandResult;
using lucent::test::run_cli;

// A diffuse plane filling the view, rendered with the albedo integrator: every pixel is the
// albedo, (0.6, 0.6, 0.6).
const char kPlaneScene[] = R"({
  "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 20},
  "film": {"width": 6, "height": 4},
  "integrator": {"type": "albedo", "spp": 2},
  "materials": {"m": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
  "shapes": [{"type": "triangles", "material": "m",
              "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
              "indices": [0,1,2, 0,2,3]}]
})";

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

using lucent::test::kernel_copy;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string join(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

/// Renders kPlaneScene with the CLI (in `cwd` when given) to a PFM file; returns the result.
CommandResult render_plane(const std::string& env, const std::string& out,
                           const std::string& cwd = "") {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/plane.json", kPlaneScene);
  std::string prefix = cwd.empty() ? env : "cd '" + cwd + "' && " + env;
  return run_cli("render '" + dir + "/plane.json' -o '" + out + "' --quiet", prefix);
}

TEST(KernelSource, EmbeddedSourcesWorkFromAnyDirectory) {
  std::string cwd = lucent::test::temp_dir();  // an empty directory: no kernels/ beside it
  std::string out = cwd + "/plane.pfm";
  CommandResult r = render_plane("env -u LUCENT_KERNEL_DIR", out, cwd);
  ASSERT_EQ(r.status, 0) << r.err;
  lucent::Image img = lucent::read_image(out);
  ASSERT_EQ(img.width, 6);
  ASSERT_EQ(img.height, 4);
  for (float v : img.rgb) EXPECT_NEAR(v, 0.6f, 1e-6f);
}

// Restores LUCENT_KERNEL_DIR as it was when the test started (a planted-bug run sets it for
// the whole test program; a test that left it unset would hide the planted kernel from every
// later test).
struct KernelDirGuard {
  std::string saved;
  bool had = false;
  KernelDirGuard() {
    if (const char* v = std::getenv("LUCENT_KERNEL_DIR")) {
      had = true;
      saved = v;
    }
  }
  ~KernelDirGuard() {
    if (had)
      ::setenv("LUCENT_KERNEL_DIR", saved.c_str(), 1);
    else
      ::unsetenv("LUCENT_KERNEL_DIR");
  }
};

TEST(KernelSource, AssembledSourceHasLineMarkers) {
  KernelDirGuard guard;
  ::unsetenv("LUCENT_KERNEL_DIR");
  std::string src = lucent::detail::assemble_kernel_source("megakernel.cl");
  EXPECT_EQ(src.rfind("#line 1 \"kernels/megakernel.cl\"\n", 0), 0u);
  EXPECT_NE(src.find("#line 1 \"kernels/shared/types.h\"\n"), std::string::npos);
  EXPECT_NE(src.find("#line 1 \"kernels/util/math.cl\"\n"), std::string::npos);
  EXPECT_EQ(src.find("#include \""), std::string::npos) << "an #include was left unexpanded";
  // after an included file, numbering resumes at the line after the #include
  std::vector<std::string> mk = lines_of(lucent::detail::read_kernel_file("megakernel.cl"));
  for (size_t i = 0; i < mk.size(); ++i)
    if (mk[i].rfind("#include \"util/math.cl\"", 0) == 0) {
      std::string marker = "#line " + std::to_string(i + 2) + " \"kernels/megakernel.cl\"\n";
      EXPECT_NE(src.find(marker), std::string::npos) << marker;
    }
  EXPECT_THROW(lucent::detail::read_kernel_file("no/such/file.cl"), lucent::Error);
}

TEST(KernelSource, KernelDirOverridesTheEmbeddedCopy) {
  std::string dir = kernel_copy();
  // an observable change: the kernel reports the colour (0.25, 0.5, 0.75) for every sample
  std::vector<std::string> mk = lines_of(read_all(dir + "/megakernel.cl"));
  bool changed = false;
  for (std::string& line : mk)
    if (line.find("out_sum[gid] =") != std::string::npos) {
      line =
          "  out_sum[gid] = (lc_accum4)(0.25f, 0.5f, 0.75f, 1.0f) * "
          "(lc_accum)params->samples_per_pass;";
      changed = true;
    }
  ASSERT_TRUE(changed) << "megakernel.cl no longer writes out_sum[gid]: update this test";
  lucent::test::write_file(dir + "/megakernel.cl", join(mk));

  std::string out = lucent::test::temp_dir() + "/plane.pfm";
  CommandResult r = render_plane("LUCENT_KERNEL_DIR='" + dir + "'", out);
  ASSERT_EQ(r.status, 0) << r.err;
  lucent::Image img = lucent::read_image(out);
  ASSERT_EQ(img.rgb.size(), 6u * 4u * 3u);
  for (size_t i = 0; i < img.rgb.size(); i += 3) {
    EXPECT_NEAR(img.rgb[i], 0.25f, 1e-6f);
    EXPECT_NEAR(img.rgb[i + 1], 0.5f, 1e-6f);
    EXPECT_NEAR(img.rgb[i + 2], 0.75f, 1e-6f);
  }

  // the library reads a directory it is given, and only then: the environment is the CLI's
  // default (SessionOptions::from_environment), not a setting the library consults
  KernelDirGuard guard;
  ::setenv("LUCENT_KERNEL_DIR", dir.c_str(), 1);
  EXPECT_EQ(lucent::SessionOptions::from_environment().kernel_dir, dir);
  EXPECT_NE(lucent::detail::read_kernel_file("megakernel.cl", dir).find("0.25f, 0.5f, 0.75f"),
            std::string::npos);
  EXPECT_EQ(lucent::detail::read_kernel_file("megakernel.cl").find("0.25f, 0.5f, 0.75f"),
            std::string::npos);
  ::unsetenv("LUCENT_KERNEL_DIR");
  EXPECT_EQ(lucent::SessionOptions::from_environment().kernel_dir, "");
}

TEST(KernelSource, MissingFileInKernelDir) {
  std::string dir = kernel_copy();
  fs::remove(dir + "/util/math.cl");
  CommandResult r =
      render_plane("LUCENT_KERNEL_DIR='" + dir + "'", lucent::test::temp_dir() + "/o.pfm");
  EXPECT_EQ(r.status, 1);
  // the error names the #include that wants the file
  std::vector<std::string> mk = lines_of(read_all(dir + "/megakernel.cl"));
  int include_line = 0;
  for (size_t i = 0; i < mk.size() && include_line == 0; ++i)
    if (mk[i].rfind("#include \"util/math.cl\"", 0) == 0) include_line = static_cast<int>(i) + 1;
  ASSERT_GT(include_line, 0) << "megakernel.cl no longer includes util/math.cl: update this test";
  EXPECT_EQ(r.err, "lucent: error: " + dir + "/megakernel.cl:" + std::to_string(include_line) +
                       ": #include \"util/math.cl\": " + dir +
                       "/util/math.cl: cannot read kernel source (kernel directory " + dir + ")\n");

  r = render_plane("LUCENT_KERNEL_DIR='" + dir + "/nowhere'", lucent::test::temp_dir() + "/o.pfm");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lucent: error: " + dir +
                       "/nowhere/megakernel.cl: cannot read kernel source (kernel directory " +
                       dir + "/nowhere)\n");
}

// A kernel directory's file that is not a regular text file is refused, naming it and what it is:
// a directory was read as an empty file (the build then failed elsewhere, on the names it lacked),
// a FIFO hung the render (until a writer came) and /dev/zero read until memory ran out. A missing
// include names the place of the #include.
TEST(KernelSource, KernelDirFilesMustBeRegularTextFiles) {
  std::string dir = kernel_copy();
  const std::string math = dir + "/util/math.cl", where = " (kernel directory " + dir + ")";
  auto read = [&dir] { lucent::detail::read_kernel_file("util/math.cl", dir); };

  fs::remove(math);
  fs::create_directory(math);
  EXPECT_EQ(lucent::test::error_of(read), math + ": is a directory, not a kernel source" + where);
  fs::remove(math);

  ASSERT_EQ(::mkfifo(math.c_str(), 0644), 0);
  // a writer that opens the FIFO once a reader waits on it (never, when it is refused), so that a
  // read that blocks ends instead of hanging the test
  std::atomic<bool> done{false};
  std::thread writer([&math, &done] {
    auto t0 = std::chrono::steady_clock::now();
    while (!done && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
      int fd = ::open(math.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) {
        ::close(fd);
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  std::string fifo_error = lucent::test::error_of(read);
  done = true;
  writer.join();
  EXPECT_EQ(fifo_error,
            math + ": is a pipe, not a kernel source (only regular files are read)" + where);
  fs::remove(math);

  lucent::test::write_file(math, std::string("float x;\n\0", 11));
  EXPECT_EQ(lucent::test::error_of(read).rfind(math + ": byte 10 is a NUL byte", 0), 0u)
      << lucent::test::error_of(read);
  lucent::test::write_file(math, std::string((16u << 20) + 1, ' '));
  EXPECT_NE(lucent::test::error_of(read).find("more than the 16.0 MiB a kernel source may have"),
            std::string::npos)
      << lucent::test::error_of(read);

  // an #include of a file that is not there: the including file and line, in the kernel directory
  lucent::test::write_file(math, "/* math */\n#include \"util/nowhere.cl\"\n");
  EXPECT_EQ(lucent::test::error_of(
                [&dir] { lucent::detail::assemble_kernel_source("util/math.cl", dir); }),
            math + ":2: #include \"util/nowhere.cl\": " + dir +
                "/util/nowhere.cl: cannot read kernel source" + where);
}

/// Inserts `bad` as line `line` (1-based) of kernels/<file> in `dir`; line 0 appends it.
int inject(const std::string& dir, const std::string& file, int line, const std::string& bad) {
  std::vector<std::string> lines = lines_of(read_all(dir + "/" + file));
  if (line <= 0) line = static_cast<int>(lines.size()) + 1;
  lines.insert(lines.begin() + (line - 1), bad);
  lucent::test::write_file(dir + "/" + file, join(lines));
  return line;
}

// The build log comes first; the last line is the one error line, naming the file and line of
// the first error (under LUCENT_KERNEL_DIR, the file there).
void expect_build_failure(const CommandResult& r, const std::string& where,
                          const std::string& file) {
  EXPECT_EQ(r.status, 1);
  EXPECT_LT(r.err.find("kernel build log:\n"), r.err.find("lucent: error: ")) << r.err;
  EXPECT_NE(r.err.find(where), std::string::npos) << "no '" << where << "' in:\n" << r.err;
  std::vector<std::string> lines = lines_of(r.err);
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().rfind("lucent: error: " + file + ":", 0), 0u) << lines.back();
  EXPECT_NE(lines.back().find(": kernel build failed: clBuildProgram: CL_BUILD_PROGRAM_FAILURE "
                              "(build log above)"),
            std::string::npos)
      << lines.back();
  EXPECT_EQ(r.err.find("lucent: error:"), r.err.rfind("lucent: error:")) << "one error line";
}

TEST(KernelSource, BuildFailureInTheMainFileNamesItsLine) {
  std::string dir = kernel_copy();
  std::vector<std::string> mk = lines_of(read_all(dir + "/megakernel.cl"));
  int at = 0;  // just before the kernel function, after every #include
  for (size_t i = 0; i < mk.size() && at == 0; ++i)
    if (mk[i].find("__kernel") != std::string::npos) at = static_cast<int>(i) + 1;
  ASSERT_GT(at, 0);
  int line = inject(dir, "megakernel.cl", at, "lucent_injected_error here;");
  CommandResult r =
      render_plane("LUCENT_KERNEL_DIR='" + dir + "'", lucent::test::temp_dir() + "/o.pfm");
  expect_build_failure(r, "kernels/megakernel.cl:" + std::to_string(line) + ":",
                       dir + "/megakernel.cl:" + std::to_string(line));
}

TEST(KernelSource, BuildFailureInAnIncludedFileNamesItsLine) {
  std::string dir = kernel_copy();
  int line = inject(dir, "util/math.cl", 0, "float lucent_injected_error(void) { return 1.0f +; }");
  CommandResult r =
      render_plane("LUCENT_KERNEL_DIR='" + dir + "'", lucent::test::temp_dir() + "/o.pfm");
  expect_build_failure(r, "kernels/util/math.cl:" + std::to_string(line) + ":",
                       dir + "/util/math.cl:" + std::to_string(line));
}

// Portability: the kernel is OpenCL C 1.2, compiled by whatever compiler the device's driver has.
// PoCL's recent clang accepts variadic macros as an extension; NVIDIA's OpenCL compiler refuses
// them ("variadic macros not supported in OpenCL"), which once broke every kernel there. Every
// kernel file (all of them are embedded) must define its macros with named parameters only.
TEST(KernelSource, NoVariadicMacrosInKernelSources) {
  ASSERT_GT(lucent::detail::kEmbeddedKernelFileCount, 30);
  for (int i = 0; i < lucent::detail::kEmbeddedKernelFileCount; ++i) {
    const auto& f = lucent::detail::kEmbeddedKernelFiles[i];
    std::vector<std::string> lines = lines_of(f.content);
    for (size_t n = 0; n < lines.size(); ++n) {
      const std::string& l = lines[n];
      std::string::size_type d = l.find_first_not_of(" \t");
      bool define = d != std::string::npos && l.compare(d, 1, "#") == 0 &&
                    l.find("define", d) != std::string::npos;
      std::string::size_type open = l.find('(');
      std::string::size_type close = open == std::string::npos ? open : l.find(')', open);
      bool variadic_params = define && close != std::string::npos &&
                             l.substr(open, close - open).find("...") != std::string::npos;
      EXPECT_FALSE(variadic_params || l.find("__VA_ARGS__") != std::string::npos)
          << "kernels/" << f.path << ":" << n + 1 << ": variadic macro: " << l;
    }
  }
}

// The same kernels through a second OpenCL C front end, when clang is installed (CI installs it
// for the fuzz stage): OpenCL C 1.2 with -pedantic, every warning an error. This catches clang
// extensions that PoCL accepts and stricter drivers may not (a variadic macro fails it too).
TEST(KernelSource, KernelsAreStrictOpenCL12ForClang) {
  if (std::system("command -v clang >/dev/null 2>&1") != 0) GTEST_SKIP() << "clang is absent";
  KernelDirGuard guard;
  ::unsetenv("LUCENT_KERNEL_DIR");
  std::string all;  // the megakernel with every feature, as --no-specialize builds it
  for (const std::string& f : lucent::render_detail::all_features()) all += "#define " + f + " 1\n";
  struct Case {
    std::string name, prefix, path;
  };
  // every feature, every feature in double precision, every feature as PoCL's CPU device builds it
  // (render_detail::device_defines) and with the light sums in double, and none (the #else
  // branches)
  std::vector<Case> cases = {
      {"megakernel", all, "megakernel.cl"},
      {"megakernel-pocl", all + "#define LC_DEVICE_POCL_CPU 1\n", "megakernel.cl"},
      {"megakernel-light-double", all + "#define LC_ACCUM_DOUBLE 1\n#define LC_LIGHT_DOUBLE 1\n",
       "megakernel.cl"},
      {"megakernel-double", all + "#define LC_DOUBLE 1\n", "megakernel.cl"},
      {"megakernel-no-features", "", "megakernel.cl"}};
  for (int i = 0; i < lucent::detail::kEmbeddedKernelFileCount; ++i) {
    std::string p = lucent::detail::kEmbeddedKernelFiles[i].path;
    if (p.rfind("test/", 0) == 0) cases.push_back({p, "", p});
  }
  ASSERT_GT(cases.size(), 5u);
  std::string dir = lucent::test::temp_dir();
  for (const Case& c : cases) {
    std::string file = dir + "/k.cl", log = dir + "/clang.log";
    lucent::test::write_file(file, c.prefix + lucent::detail::assemble_kernel_source(c.path));
    std::string cmd =
        "clang -x cl -cl-std=CL1.2 -fsyntax-only -pedantic -Werror -Xclang "
        "-finclude-default-header '" +
        file + "' >'" + log + "' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << c.name << ":\n" << lucent::test::read_file(log);
  }
}

// NVIDIA's OpenCL compiler ignores #line in its diagnostics' places: "<kernel>:3417:1: error: ..."
// gives the physical line of the assembled source. lucent maps such places back through the
// #line markers, so the error line names kernels/<file>:<line> on every driver. (Checked against
// NVIDIA's real log of an injected error: BENCHMARKS.md, "GPU".)
TEST(KernelSource, PhysicalLinePlacesMapThroughLineMarkers) {
  KernelDirGuard guard;
  ::unsetenv("LUCENT_KERNEL_DIR");
  std::string src = lucent::detail::assemble_kernel_source("megakernel.cl");
  std::vector<std::string> phys = lines_of(src);
  std::vector<std::string> mk = lines_of(lucent::detail::read_kernel_file("megakernel.cl"));
  std::vector<std::string> math = lines_of(lucent::detail::read_kernel_file("util/math.cl"));
  auto index_of = [](const std::vector<std::string>& v, const std::string& what) {
    for (size_t i = 0; i < v.size(); ++i)
      if (v[i].find(what) != std::string::npos) return static_cast<long>(i) + 1;
    return 0L;
  };
  long k_phys = index_of(phys, "void lucent_render("), k_file = index_of(mk, "void lucent_render(");
  ASSERT_GT(k_phys, k_file);  // the includes come before it
  ASSERT_GT(k_file, 0);
  EXPECT_EQ(lucent::cl_util::source_place(src, k_phys),
            "kernels/megakernel.cl:" + std::to_string(k_file));
  // a line of an included file (its last line: the physical line before the next marker)
  long m_first = index_of(phys, "#line 1 \"kernels/util/math.cl\"") + 1;
  ASSERT_GT(m_first, 1);
  long m_last = m_first + static_cast<long>(math.size()) - 1;
  EXPECT_EQ(phys[m_last - 1], math.back());
  EXPECT_EQ(lucent::cl_util::source_place(src, m_last),
            "kernels/util/math.cl:" + std::to_string(math.size()));
  EXPECT_EQ(lucent::cl_util::source_place(src, static_cast<long>(phys.size()) + 5), "");
  EXPECT_EQ(lucent::cl_util::source_place(src, 0), "");

  std::string log =
      "1 error generated.\n<kernel>:" + std::to_string(k_phys) +
      ":15: error: unknown type name 'x'\nx here;\n^\n<kernel>:" + std::to_string(m_last) +
      ":3: note: expanded from macro 'Y'\n" +
      "kernels/bvh/traverse.cl:12:1: warning: left as it is";
  std::string mapped = lucent::cl_util::map_source_places(log, src);
  EXPECT_EQ(mapped, "1 error generated.\nkernels/megakernel.cl:" + std::to_string(k_file) +
                        ":15: error: unknown type name 'x'\nx here;\n^\nkernels/util/math.cl:" +
                        std::to_string(math.size()) + ":3: note: expanded from macro 'Y'\n" +
                        "kernels/bvh/traverse.cl:12:1: warning: left as it is");
  EXPECT_EQ(lucent::cl_util::first_error_place(mapped),
            "kernels/megakernel.cl:" + std::to_string(k_file) + ":15");
}

}  // namespace

}  // namespace test_kernel_source
