// lucent's on-disk program cache: hits on a second build, keys on options, detects corrupt and
// truncated entries and rebuilds them (the rebuilt program still runs).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "support.hpp"

namespace test_program_cache {

namespace {

namespace fs = std::filesystem;
using lucent::cl_util::ProgramBuildInfo;

struct CacheDir {
  std::string dir = lucent::test::temp_dir() + "/cache";
};

// A file of `bytes` bytes named as the cache names entry `i`, last used `hours_ago` hours ago.
std::string old_entry(const std::string& dir, unsigned i, size_t bytes, int hours_ago) {
  char name[32];
  std::snprintf(name, sizeof name, "/%016x.bin", i);
  fs::create_directories(dir);
  lucent::test::write_file(dir + name, std::string(bytes, 'x'));
  fs::last_write_time(dir + name, fs::file_time_type::clock::now() - std::chrono::hours(hours_ago));
  return dir + name;
}

// Runs the layout probe kernel: a built program that really works returns sizeof(lc_material).
unsigned run_probe(lucent::cl_util::Context& ctx, cl::Program& p) {
  cl::Kernel k(p, "lucent_layout_probe");
  cl::Buffer out(ctx.context, CL_MEM_WRITE_ONLY, 4096);
  k.setArg(0, out);
  ctx.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NullRange);
  unsigned v = 0;
  ctx.queue.enqueueReadBuffer(out, CL_TRUE, 0, sizeof v, &v);
  return v;
}

TEST(ProgramCache, HitsMissesAndRebuildsCorruptEntries) {
  CacheDir cache;
  lucent::cl_util::Context ctx{lucent::test::device()};
  std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  ProgramBuildInfo a, b, c;
  cl::Program p1 = lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &a);
  EXPECT_FALSE(a.cache_hit);
  ASSERT_TRUE(fs::exists(a.cache_file)) << a.cache_file;
  cl::Program p2 = lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &b);
  EXPECT_TRUE(b.cache_hit);
  EXPECT_EQ(run_probe(ctx, p2), 64u);

  // other options, other entry
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_UNUSED", cache.dir, &c);
  EXPECT_FALSE(c.cache_hit);
  EXPECT_NE(c.cache_file, a.cache_file);

  // flip a byte in the middle of the binary: checksum mismatch, rebuilt, still runs
  {
    std::fstream f(a.cache_file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(0, std::ios::end);
    auto size = static_cast<long>(f.tellg());
    f.seekp(size - 17);
    char x = 0;
    f.seekg(size - 17);
    f.read(&x, 1);
    x = static_cast<char>(x ^ 0x5a);
    f.seekp(size - 17);
    f.write(&x, 1);
  }
  ProgramBuildInfo d;
  cl::Program p3 = lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &d);
  EXPECT_FALSE(d.cache_hit);
  EXPECT_NE(d.note.find("checksum"), std::string::npos) << d.note;
  EXPECT_EQ(run_probe(ctx, p3), 64u);
  ProgramBuildInfo e;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &e);
  EXPECT_TRUE(e.cache_hit) << "the rebuilt entry is written back";

  // truncate: detected
  fs::resize_file(a.cache_file, fs::file_size(a.cache_file) / 2);
  ProgramBuildInfo f;
  cl::Program p4 = lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &f);
  EXPECT_FALSE(f.cache_hit);
  EXPECT_FALSE(f.note.empty());
  EXPECT_EQ(run_probe(ctx, p4), 64u);

  // garbage file with the right name: bad header, rebuilt
  lucent::test::write_file(a.cache_file, "not a cache entry");
  ProgramBuildInfo g;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &g);
  EXPECT_FALSE(g.cache_hit);
  EXPECT_NE(g.note.find("header"), std::string::npos) << g.note;

  // clear removes the entries; a cache directory that is a file is an error, not "removed 0"
  EXPECT_EQ(lucent::test::error_of([] { lucent::cl_util::clear_program_cache("/etc/passwd"); }),
            "/etc/passwd: not a directory (the kernel cache, LUCENT_CACHE_DIR)");
  EXPECT_EQ(lucent::cl_util::clear_program_cache(cache.dir + "/none"), 0);
  // and so is one below a file (it was "removed 0", as for a cache not made yet)
  EXPECT_EQ(lucent::test::error_of([] { lucent::cl_util::clear_program_cache("/etc/passwd/sub"); }),
            "/etc/passwd/sub: cannot be the kernel cache (LUCENT_CACHE_DIR): /etc/passwd is not a "
            "directory");
  EXPECT_EQ(lucent::test::error_of([] { lucent::cl_util::program_cache_usage("/etc/passwd/a/b"); }),
            "/etc/passwd/a/b: cannot be the kernel cache (LUCENT_CACHE_DIR): /etc/passwd is not a "
            "directory");
  // a path that cannot be looked at says why (it said "not a directory")
  const std::string long_name = "/tmp/" + std::string(300, '0') + "/x";
  EXPECT_EQ(lucent::test::error_of([&] { lucent::cl_util::clear_program_cache(long_name); }),
            long_name + ": cannot look at the kernel cache (" +
                std::make_error_code(std::errc::filename_too_long).message() + ")");
  EXPECT_GE(lucent::cl_util::clear_program_cache(cache.dir), 2);
  ProgramBuildInfo h;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2", cache.dir, &h);
  EXPECT_FALSE(h.cache_hit);
}

// Every field of an entry's header is checked before the binary is used. The entry layout
// (program_cache.cpp): the magic line, the key's length (8 bytes), the key, the binary's length
// and checksum (8 bytes each), the binary. Each damaged copy of a good entry is a miss whose note
// names the fault, the program is rebuilt and runs, and a good entry is written back.
TEST(ProgramCache, DamagedHeadersAreRebuilt) {
  CacheDir cache;
  lucent::cl_util::Context ctx{lucent::test::device()};
  std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  const std::string options = "-cl-std=CL1.2 -D LC_DAMAGED_HEADER_TEST";
  ProgramBuildInfo first;
  lucent::cl_util::build_program_cached(ctx, src, options, cache.dir, &first);
  const std::string good = lucent::test::read_file(first.cache_file);
  const std::string magic = "LUCENT-PROGRAM-CACHE-1\n";
  ASSERT_EQ(good.compare(0, magic.size(), magic), 0);
  auto u64_at = [&good](size_t at) {
    std::uint64_t v = 0;
    std::memcpy(&v, good.data() + at, sizeof v);
    return v;
  };
  auto with_u64 = [](std::string bytes, size_t at, std::uint64_t v) {
    std::memcpy(&bytes[at], &v, sizeof v);
    return bytes;
  };
  const size_t key_at = magic.size() + 8;
  const std::uint64_t key_len = u64_at(magic.size());
  const size_t bin_len_at = key_at + key_len, bin_at = bin_len_at + 16;
  const std::uint64_t bin_len = u64_at(bin_len_at);
  ASSERT_EQ(good.size(), bin_at + bin_len) << "the layout above";
  std::string other_key = good;
  other_key[key_at + key_len / 2] ^= 0x20;
  std::string no_binary = with_u64(good.substr(0, bin_at), bin_len_at, 0);
  const struct {
    const char* what;
    std::string bytes;
    const char* note;
  } cases[] = {
      {"empty file", "", "bad header"},
      {"magic line only", magic, "bad header"},
      {"other magic", "LUCENT-PROGRAM-CACHE-0\n" + good.substr(magic.size()), "bad header"},
      {"key longer than the file", with_u64(good, magic.size(), good.size()), "bad header"},
      {"key length 2^63", with_u64(good, magic.size(), 1ull << 63), "bad header"},
      {"key one byte short", with_u64(good, magic.size(), key_len - 1), "stale or colliding key"},
      {"another program's key", other_key, "stale or colliding key"},
      {"zero binary size", no_binary, "bad binary size"},
      {"binary size 2^40", with_u64(good, bin_len_at, 1ull << 40), "bad binary size"},
      {"binary one byte longer than said", good + "x", "truncated or oversized"},
      {"binary size one more than there is", with_u64(good, bin_len_at, bin_len + 1),
       "truncated or oversized"},
      {"checksum off by one", with_u64(good, bin_len_at + 8, u64_at(bin_len_at + 8) + 1),
       "checksum mismatch"},
  };
  for (const auto& c : cases) {
    lucent::test::write_file(first.cache_file, c.bytes);
    ProgramBuildInfo damaged, again;
    cl::Program p = lucent::cl_util::build_program_cached(ctx, src, options, cache.dir, &damaged);
    EXPECT_FALSE(damaged.cache_hit) << c.what;
    EXPECT_NE(damaged.note.find(c.note), std::string::npos) << c.what << ": " << damaged.note;
    EXPECT_EQ(run_probe(ctx, p), 64u) << c.what;
    // written back (not always byte for byte: PoCL's binary gains the kernels launched since)
    lucent::cl_util::build_program_cached(ctx, src, options, cache.dir, &again);
    EXPECT_TRUE(again.cache_hit) << c.what << ": the rebuilt entry is written back";
  }
}

TEST(ProgramCache, CanBeDisabled) {
  lucent::cl_util::Context ctx{lucent::test::device()};
  ProgramBuildInfo a;
  cl::Program p = lucent::cl_util::build_program_cached(
      ctx, lucent::detail::assemble_kernel_source("test/layout_probe.cl"), "-cl-std=CL1.2", "", &a);
  EXPECT_FALSE(a.cache_hit);
  EXPECT_TRUE(a.cache_file.empty());
  EXPECT_EQ(run_probe(ctx, p), 64u);
}

// PoCL keeps its own cache unless POCL_KERNEL_CACHE reads as off to PoCL (a value not starting
// with 1); other drivers: none that lucent knows of.
TEST(ProgramCache, DriverCacheIsPoclsWhileItIsOn) {
  lucent::cl_util::Device pocl, nvidia;
  pocl.info.platform = "Portable Computing Language";
  nvidia.info.platform = "NVIDIA CUDA";
  const std::string kPocl = "PoCL's kernel cache";
  {
    lucent::test::ScopedEnv unset("POCL_KERNEL_CACHE", nullptr);
    EXPECT_EQ(lucent::cl_util::driver_program_cache(pocl), kPocl);
    EXPECT_EQ(lucent::cl_util::driver_program_cache(nvidia), "");
  }
  for (const char* on : {"1", "10", "1x"}) {
    lucent::test::ScopedEnv env("POCL_KERNEL_CACHE", on);
    EXPECT_EQ(lucent::cl_util::driver_program_cache(pocl), kPocl) << on;
  }
  for (const char* off : {"0", "no", "yes", "", " 1"}) {
    lucent::test::ScopedEnv env("POCL_KERNEL_CACHE", off);
    EXPECT_EQ(lucent::cl_util::driver_program_cache(pocl), "") << "'" << off << "'";
  }
}

// A program PoCL's kernel cache gives back damaged (an empty program.bc, after a power loss: PoCL
// does not fsync) has no kernel: the error names the cache and the remedy (it said only
// "clCreateKernel: CL_INVALID_KERNEL_NAME"). Removing the directory, as it says, mends it.
TEST(ProgramCache, ADamagedPoclCacheIsNamed) {
  const std::string dir = lucent::test::temp_dir(), pocl = dir + "/pocl";
  const std::string scene = dir + "/s.json";
  lucent::test::write_file(scene, R"({
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "albedo", "spp": 1},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.25, 0.75]}},
    "shapes": [{"type": "sphere", "center": [0, 0, -3], "radius": 1, "material": "m"}]
  })");
  const std::string env = "POCL_CACHE_DIR='" + pocl + "' LUCENT_CACHE_DIR='" + dir + "/lc'";
  const std::string cmd = "render '" + scene + "' -q -o '" + dir + "/o.pfm'";
  auto r = lucent::test::run_cli(cmd, env);
  ASSERT_EQ(r.status, 0) << r.err;
  int damaged = 0;
  for (const auto& e : fs::recursive_directory_iterator(pocl))
    if (e.path().filename() == "program.bc") {
      fs::resize_file(e.path(), 0);
      ++damaged;
    }
  if (damaged == 0) GTEST_SKIP() << "no PoCL cache entry here (not PoCL, or its cache is off)";
  r = lucent::test::run_cli(cmd, env);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err,
            "lucent: error: clCreateKernel: CL_INVALID_KERNEL_NAME: the program PoCL's "
            "kernel cache gave back has no kernel: that cache, in " +
                pocl + ", may be damaged; remove the directory\n");
  fs::remove_all(pocl);
  EXPECT_EQ(lucent::test::run_cli(cmd, env).status, 0);
}

// A deferred entry is written by store(), not by the build; dropped unstored it writes nothing
// and releases its lock (the next build is a miss that does not wait).
TEST(ProgramCache, DeferredEntriesAreWrittenByStore) {
  CacheDir c;
  lucent::cl_util::Context ctx("");
  std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  const std::string options = "-cl-std=CL1.2 -D LC_DEFERRED_ENTRY_TEST";
  ProgramBuildInfo a, b, d, e;
  {
    lucent::cl_util::DeferredEntry dropped;
    lucent::cl_util::build_program_cached(ctx, src, options, c.dir, &a, &dropped);
    EXPECT_TRUE(dropped.pending());
  }
  EXPECT_FALSE(fs::exists(a.cache_file));
  lucent::cl_util::DeferredEntry entry;
  cl::Program p = lucent::cl_util::build_program_cached(ctx, src, options, c.dir, &b, &entry);
  EXPECT_FALSE(b.cache_hit);
  ASSERT_TRUE(entry.pending());
  EXPECT_FALSE(fs::exists(b.cache_file));
  EXPECT_EQ(run_probe(ctx, p), 64u);  // a launch first, as the session does
  entry.store(p);
  EXPECT_FALSE(entry.pending());
  EXPECT_TRUE(fs::is_regular_file(b.cache_file));
  lucent::cl_util::DeferredEntry none;
  cl::Program q = lucent::cl_util::build_program_cached(ctx, src, options, c.dir, &d, &none);
  EXPECT_TRUE(d.cache_hit);
  EXPECT_FALSE(none.pending()) << "a hit leaves nothing to store";
  EXPECT_EQ(run_probe(ctx, q), 64u);
  lucent::cl_util::build_program_cached(ctx, src, options, "", &e, &none);
  EXPECT_FALSE(e.cache_hit);
  EXPECT_FALSE(none.pending()) << "no cache, nothing to store";
}

TEST(ProgramCache, CliClearsTheCache) {
  std::string dir = lucent::test::temp_dir() + "/clicache";
  auto r = lucent::test::run_cli("cache dir", "LUCENT_CACHE_DIR='" + dir + "'");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find(dir), std::string::npos);
  fs::create_directories(dir);
  lucent::test::write_file(dir + "/0123456789abcdef.bin", "x");
  lucent::test::write_file(dir + "/0123456789abcdef.bin.lock", "");
  // an interrupted write's temporary file (its process gone: a child reaped), and a write in
  // progress (this process's), which clear removed under it
  const pid_t gone = ::fork();
  if (gone == 0) ::_exit(0);
  ::waitpid(gone, nullptr, 0);
  const std::string dead = "/.0123456789abcdef.bin.tmp-" + std::to_string(gone) + "-0",
                    live = "/.0123456789abcdef.bin.tmp-" + std::to_string(::getpid()) + "-3";
  lucent::test::write_file(dir + dead, "x");
  lucent::test::write_file(dir + live, "x");
  // files the cache did not write stay, whatever their extension (a cache directory given by
  // mistake, ".", lost every *.bin file in it)
  lucent::test::write_file(dir + "/weights.bin", "keep");
  lucent::test::write_file(dir + "/0123456789ABCDEF.bin", "keep");
  // nor a directory of an entry's name (an empty one was removed and counted as a program)
  fs::create_directories(dir + "/0000000000000000.bin");
  fs::create_directories(dir + "/fedcba9876543210.bin");
  lucent::test::write_file(dir + "/fedcba9876543210.bin/data.txt", "keep");
  // nor a user's file whose name starts like an entry's (it was counted and removed), nor a link
  // of an entry's name (info counted it, and its target's size, where clear left it)
  lucent::test::write_file(dir + "/0123456789abcdef.bin.old.bin", "keep");
  lucent::test::write_file(dir + "/.0123456789abcdef.bin.tmp-notes", "keep");
  lucent::test::write_file(dir + "/elsewhere", std::string(5000, 'x'));
  fs::create_symlink(dir + "/elsewhere", dir + "/1111111111111111.bin");
  r = lucent::test::run_cli("cache info", "LUCENT_CACHE_DIR='" + dir + "'");
  EXPECT_NE(r.out.find("programs: 1"), std::string::npos) << r.out;
  r = lucent::test::run_cli("cache clear", "LUCENT_CACHE_DIR='" + dir + "'");
  EXPECT_EQ(r.status, 0);
  // as many as info counted: the entry (its write's temporary file went too, uncounted)
  EXPECT_NE(r.out.find("removed 1 "), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir + "/weights.bin"));
  EXPECT_TRUE(fs::exists(dir + "/0123456789ABCDEF.bin"));
  EXPECT_TRUE(fs::is_directory(dir + "/0000000000000000.bin"));
  EXPECT_TRUE(fs::exists(dir + "/fedcba9876543210.bin/data.txt"));
  EXPECT_TRUE(fs::exists(dir + "/0123456789abcdef.bin.old.bin"));
  EXPECT_TRUE(fs::exists(dir + "/.0123456789abcdef.bin.tmp-notes"));
  EXPECT_TRUE(fs::is_symlink(dir + "/1111111111111111.bin"));
  EXPECT_FALSE(fs::exists(dir + "/0123456789abcdef.bin.lock"));
  EXPECT_FALSE(fs::exists(dir + dead));
  EXPECT_TRUE(fs::exists(dir + live));
  // on PoCL with its cache on, where sessions leave caching to PoCL, it says so
  bool pocl = false;
  for (const lucent::cl_util::Device& d : lucent::cl_util::enumerate_devices())
    pocl = pocl || !lucent::cl_util::driver_program_cache(d).empty();
  EXPECT_EQ(r.out.find("kernels are cached by PoCL") != std::string::npos, pocl) << r.out;
  r = lucent::test::run_cli("cache clear", "POCL_KERNEL_CACHE=0 LUCENT_CACHE_DIR='" + dir + "'");
  EXPECT_EQ(r.out.find("kernels are cached by PoCL"), std::string::npos) << r.out;
  // with it off, sessions build from source (keeps_program_binaries): it says that too
  bool pocl_device = false;
  for (const lucent::cl_util::Device& d : lucent::cl_util::enumerate_devices())
    pocl_device = pocl_device || !lucent::cl_util::keeps_program_binaries(d);
  EXPECT_EQ(r.out.find("kernels are built from source each time: PoCL's kernel cache is off") !=
                std::string::npos,
            pocl_device)
      << r.out;
  EXPECT_FALSE(fs::exists(dir + "/0123456789abcdef.bin"));
}

// Past the limit, the least recently used entries go first, with their build locks (unless held),
// never the entry kept (the one just written), and nothing the cache did not write.
TEST(ProgramCache, EvictsTheLeastRecentlyUsedEntries) {
  const std::string dir = lucent::test::temp_dir() + "/cache";
  std::vector<std::string> e;
  for (unsigned i = 0; i < 5; ++i)
    e.push_back(old_entry(dir, i, 100000, 5 - int(i)));  // e[0] oldest
  for (int i : {0, 1, 4}) lucent::test::write_file(e[i] + ".lock", "");
  const std::string tmp = dir + "/.0000000000000000.bin.tmp-1-0";
  for (const std::string& other : {dir + "/weights.bin", dir + "/0000000000ABCDEF.bin", tmp}) {
    lucent::test::write_file(other, std::string(300000, 'y'));
    fs::last_write_time(other, fs::file_time_type::clock::now() - std::chrono::hours(9));
  }
  lucent::cl_util::ProgramCacheUsage usage = lucent::cl_util::program_cache_usage(dir);
  EXPECT_EQ(usage.programs, 5);
  EXPECT_EQ(usage.bytes, 500000u);

  EXPECT_EQ(lucent::cl_util::evict_program_cache(dir, 0), 0) << "0: no limit";
  EXPECT_EQ(lucent::cl_util::evict_program_cache(dir, 500000), 0) << "at the limit";
  EXPECT_EQ(lucent::test::error_of([] { lucent::cl_util::evict_program_cache("/etc/passwd", 1); }),
            "");
  EXPECT_EQ(lucent::cl_util::program_cache_usage(dir).programs, 5);

  // e[1]'s lock is held by a builder: it stays
  int fd = ::open((e[1] + ".lock").c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  EXPECT_EQ(lucent::cl_util::evict_program_cache(dir, 250000, e[4]), 3);
  ::close(fd);
  for (int i : {0, 1, 2}) EXPECT_FALSE(fs::exists(e[i])) << i;
  for (int i : {3, 4}) EXPECT_TRUE(fs::exists(e[i])) << i;
  EXPECT_FALSE(fs::exists(e[0] + ".lock"));
  EXPECT_TRUE(fs::exists(e[1] + ".lock")) << "a held lock was removed";
  EXPECT_TRUE(fs::exists(e[4] + ".lock")) << "the lock of an entry still there was removed";
  for (const std::string& other : {dir + "/weights.bin", dir + "/0000000000ABCDEF.bin", tmp})
    EXPECT_TRUE(fs::exists(other)) << other;
  usage = lucent::cl_util::program_cache_usage(dir);
  EXPECT_EQ(usage.programs, 2);
  EXPECT_EQ(usage.bytes, 200000u);

  // the entry kept stays even when it is the oldest and alone over the limit; free locks of
  // entries gone go at the next eviction
  EXPECT_EQ(lucent::cl_util::evict_program_cache(dir, 1, e[3]), 1);
  EXPECT_TRUE(fs::exists(e[3]));
  EXPECT_FALSE(fs::exists(e[4]));
  EXPECT_FALSE(fs::exists(e[1] + ".lock"));
  EXPECT_FALSE(fs::exists(e[4] + ".lock"));
}

// LUCENT_CACHE_MAX_MB: MiB, fractions allowed, 0 for no limit; what is not a size warns once and
// keeps the default.
TEST(ProgramCache, LimitFromTheEnvironment) {
  const std::uint64_t kDefault = 256ull << 20;
  {
    lucent::test::ScopedEnv unset("LUCENT_CACHE_MAX_MB", nullptr);
    EXPECT_EQ(lucent::cl_util::program_cache_max_bytes(), kDefault);
  }
  const struct {
    const char* value;
    std::uint64_t bytes;
  } good[] = {{"", kDefault},       {"0", 0},    {"1", 1u << 20}, {"1.5", 3u << 19},
              {"4096", 1ull << 32}, {"1e-9", 1}, {"1e-400", 1}};  // (it underflowed to 0: no limit)
  for (const auto& g : good) {
    lucent::test::ScopedEnv env("LUCENT_CACHE_MAX_MB", g.value);
    lucent::test::CaptureWarnings warnings;
    EXPECT_EQ(lucent::cl_util::program_cache_max_bytes(), g.bytes) << "'" << g.value << "'";
    EXPECT_EQ(warnings.all().size(), 0u) << "'" << g.value << "'";
  }
  // (plain decimal, as the command line's numbers: strtod took "0x10" and " 16")
  for (const char* bad : {"lots", "-1", "12MB", "nan", "inf", "1,5", "0x10", " 16", "16 "}) {
    lucent::test::ScopedEnv env("LUCENT_CACHE_MAX_MB", bad);
    lucent::test::CaptureWarnings warnings;
    EXPECT_EQ(lucent::cl_util::program_cache_max_bytes(), kDefault) << bad;
    ASSERT_EQ(warnings.all().size(), 1u) << bad;
    EXPECT_EQ(warnings.all()[0],
              std::string("LUCENT_CACHE_MAX_MB='") + bad +
                  "' is not a size in MiB (a decimal number, 0 for no limit); the "
                  "kernel cache keeps its default limit of 256 MiB");
  }
}

// Writing an entry evicts past LUCENT_CACHE_MAX_MB, least recently used first, where a load is a
// use; 0 keeps everything.
TEST(ProgramCache, WritesEvictLeastRecentlyUsedEntries) {
  CacheDir cache;
  lucent::cl_util::Context ctx{lucent::test::device()};
  const std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  ProgramBuildInfo a, hit, b, again;
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_EVICT_A", cache.dir, &a);
  ASSERT_TRUE(fs::exists(a.cache_file));
  const auto size_a = fs::file_size(a.cache_file);
  // three old entries of 1 MiB, and `a` older still, then loaded: a use
  std::vector<std::string> old;
  for (unsigned i = 0; i < 3; ++i) old.push_back(old_entry(cache.dir, i, 1u << 20, 3 - int(i)));
  fs::last_write_time(a.cache_file, fs::file_time_type::clock::now() - std::chrono::hours(10));
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_EVICT_A", cache.dir, &hit);
  ASSERT_TRUE(hit.cache_hit);

  // a limit of 1.5 MiB more than four entries like `a`: writing `b` removes two old entries
  const std::string limit = std::to_string(1.5 + 4.0 * double(size_a) / (1 << 20));
  {
    lucent::test::ScopedEnv env("LUCENT_CACHE_MAX_MB", limit.c_str());
    cl::Program p = lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_EVICT_B",
                                                          cache.dir, &b);
    EXPECT_EQ(run_probe(ctx, p), 64u);
  }
  EXPECT_FALSE(b.cache_hit);
  EXPECT_TRUE(fs::exists(b.cache_file));
  EXPECT_TRUE(fs::exists(a.cache_file)) << "the entry just loaded was evicted";
  EXPECT_FALSE(fs::exists(old[0]));
  EXPECT_FALSE(fs::exists(old[1]));
  EXPECT_TRUE(fs::exists(old[2]));
  lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_EVICT_A", cache.dir, &again);
  EXPECT_TRUE(again.cache_hit);

  // 0: no limit, however small the last one was
  for (unsigned i = 3; i < 6; ++i) old.push_back(old_entry(cache.dir, i, 1u << 20, 20));
  ProgramBuildInfo c;
  {
    lucent::test::ScopedEnv env("LUCENT_CACHE_MAX_MB", "0");
    lucent::cl_util::build_program_cached(ctx, src, "-cl-std=CL1.2 -D LC_EVICT_C", cache.dir, &c);
  }
  EXPECT_FALSE(c.cache_hit);
  for (size_t i = 2; i < old.size(); ++i) EXPECT_TRUE(fs::exists(old[i])) << i;
  EXPECT_EQ(lucent::cl_util::program_cache_usage(cache.dir).programs, 7);
}

// `lucent cache info`: the directory, the number and size of the entries (nothing else the
// directory holds), the limit.
TEST(ProgramCache, CliReportsTheCacheSize) {
  const std::string dir = lucent::test::temp_dir() + "/clicache";
  const std::string env = "LUCENT_CACHE_DIR='" + dir + "' ";
  auto r = lucent::test::run_cli("cache info", env);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("directory: " + dir + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("programs: 0, 0 bytes\n"), std::string::npos) << r.out;
  old_entry(dir, 1, 1000, 1);
  old_entry(dir, 2, 2072, 2);
  lucent::test::write_file(dir + "/0000000000000001.bin.lock", "");
  lucent::test::write_file(dir + "/.0000000000000003.bin.tmp-1-0", std::string(500, 'x'));
  lucent::test::write_file(dir + "/weights.bin", std::string(700, 'x'));
  r = lucent::test::run_cli("cache info", env);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("programs: 2, 3072 bytes (3.0 KiB)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("limit: 256.0 MiB (LUCENT_CACHE_MAX_MB"), std::string::npos) << r.out;
  r = lucent::test::run_cli("cache info", env + "LUCENT_CACHE_MAX_MB=0.5");
  EXPECT_NE(r.out.find("limit: 512.0 KiB (LUCENT_CACHE_MAX_MB"), std::string::npos) << r.out;
  r = lucent::test::run_cli("cache info", env + "LUCENT_CACHE_MAX_MB=0");
  EXPECT_NE(r.out.find("limit: none (LUCENT_CACHE_MAX_MB"), std::string::npos) << r.out;
  r = lucent::test::run_cli("cache info", env + "LUCENT_CACHE_MAX_MB=big");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("limit: 256.0 MiB (LUCENT_CACHE_MAX_MB"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("LUCENT_CACHE_MAX_MB='big' is not a size in MiB"), std::string::npos)
      << r.err;
  r = lucent::test::run_cli("cache info", "LUCENT_CACHE_DIR=off");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("directory: (disabled)\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("programs:"), std::string::npos) << r.out;
  r = lucent::test::run_cli("cache info", "LUCENT_CACHE_DIR=/etc/passwd");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("/etc/passwd: not a directory"), std::string::npos) << r.err;
}

// A session waiting for another process's build lock stops waiting once its render is cancelled,
// and builds nothing (it built without the lock until 30 Nov 2026): `lucent render` under `timeout`
// (one SIGTERM) waited 600 s for a holder that had been stopped (Ctrl-Z) in its build, then
// rendered and wrote "interrupted".
TEST(ProgramCache, CancelledSessionStopsWaitingForABuildLock) {
  const lucent::Scene scene = lucent::test::scene_from(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 4, "height": 4},
    "integrator": {"type": "albedo", "spp": 1},
    "materials": {"m": {"type": "diffuse"}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]
  })");
  lucent::SessionOptions o = lucent::test::session_options();
  if (o.cache_dir == "off") GTEST_SKIP() << "LUCENT_CACHE_DIR=off: no build locks";
  // the lock's name (the key's hash, whatever the directory), from a first session's build
  const std::string first = lucent::test::temp_dir(), second = lucent::test::temp_dir();
  o.cache_dir = first;
  lucent::Renderer(o).set_scene(scene);
  std::string lock;
  for (const auto& e : fs::directory_iterator(first))
    if (e.path().extension() == ".lock") lock = e.path().filename().string();
  ASSERT_FALSE(lock.empty());

  // another process's lock, held until the session returns (at most 6 s)
  int fd = ::open((second + "/" + lock).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  std::atomic<bool> done{false};
  std::thread holder([fd, &done] {
    auto t0 = std::chrono::steady_clock::now();
    while (!done && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(6))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ::close(fd);
  });
  o.cache_dir = second;
  lucent::Renderer r(o);
  std::atomic<bool> cancel{true};
  r.set_cancel_flag(&cancel);
  auto t0 = std::chrono::steady_clock::now();
  std::string error = lucent::test::error_of([&] { r.set_scene(scene); });
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  done = true;
  holder.join();
  // (it then built the kernel without the lock: a Ctrl-C in Python waited for that build)
  EXPECT_EQ(error.rfind("kernel build cancelled while it waited for another process's build of "
                        "the same kernel (" +
                            second + "/" + lock + ")",
                        0),
            0u)
      << error;
  EXPECT_LT(seconds, 4.0) << "waited for the lock although the render was cancelled";

  // a cancel() left from a render that had ended is dropped by the next set_scene, as by the
  // next render: it waits for the lock's holder (here 0.5 s) and builds (it gave up at once)
  const int fd2 = ::open((second + "/" + lock).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd2, 0);
  ASSERT_EQ(::flock(fd2, LOCK_EX), 0);
  std::thread holder2([fd2] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::close(fd2);
  });
  lucent::Renderer left(o);
  left.cancel();  // (no render runs: dropped)
  error = lucent::test::error_of([&] { left.set_scene(scene); });
  holder2.join();
  EXPECT_EQ(error, "");
}

}  // namespace

namespace {

// `lucent cache clear` that cannot remove an entry (a read-only directory, for a user other than
// root) says so and fails: it said "removed 0 cached program(s)", status 0, and the entry stayed.
TEST(ProgramCache, AClearThatCannotRemoveAnEntryFails) {
  const bool root = ::geteuid() == 0;
  if (root && std::system("command -v setpriv >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "root ignores the directory's permissions, and setpriv is absent";
  const std::string dir = lucent::test::temp_dir() + "/cache";
  std::filesystem::create_directories(dir);
  lucent::test::write_file(dir + "/0123456789abcdef.bin", "an entry");
  ::chmod(lucent::test::temp_dir().c_str(), 0755);
  ::chmod(dir.c_str(), 0555);
  const std::string as_user = (root ? "setpriv --reuid 65534 --regid 65534 --clear-groups " : "") +
                              std::string("env LUCENT_CACHE_DIR='") + dir + "'";
  const lucent::test::CommandResult r = lucent::test::run_cli("cache clear", as_user);
  ::chmod(dir.c_str(), 0755);
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_EQ(r.err,
            "lucent: error: cannot remove 1 cached program(s) (" + dir + "/0123456789abcdef.bin: " +
                std::make_error_code(std::errc::permission_denied).message() + "); removed 0\n");
  EXPECT_TRUE(std::filesystem::exists(dir + "/0123456789abcdef.bin"));
}

}  // namespace

}  // namespace test_program_cache
