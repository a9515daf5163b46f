// `lucent cache clear|dir|info`: the on-disk cache of built kernel programs
// (src/cl/program_cache.hpp).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <string>

#include "cl/context.hpp"
#include "cl/program_cache.hpp"
#include "cli/commands.hpp"
#include "core/host_memory.hpp"
#include "core/text.hpp"
#include "lucent/error.hpp"

namespace lucent::cli {

namespace {
std::string g_action;

// On PoCL, sessions leave caching to PoCL's own cache (cl/program_cache.hpp): says where it is,
// or that it is off.
void say_where_pocl_caches() {
  try {
    for (const cl_util::Device& d : cl_util::enumerate_devices()) {
      if (cl_util::keeps_program_binaries(d)) continue;
      if (!cl_util::driver_program_cache(d).empty())
        // (the directory PoCL uses: it said "default ~/.cache/pocl/kcache" whatever
        // XDG_CACHE_HOME chose)
        std::printf(
            "%s: kernels are cached by PoCL in %s (POCL_CACHE_DIR), not here; remove that "
            "directory to rebuild them from source\n",
            d.info.name.c_str(), one_line(cl_util::pocl_cache_dir()).c_str());
      else
        std::printf(
            "%s: kernels are built from source each time: PoCL's kernel cache is off "
            "(POCL_KERNEL_CACHE), and lucent keeps no PoCL programs here\n",
            d.info.name.c_str());
      return;
    }
  } catch (const Error&) {
    // no OpenCL platform: nothing more to say
  }
}

// The size of lucent's cache, its limit (LUCENT_CACHE_MAX_MB) and where PoCL caches instead.
void print_info(const std::string& dir) {
  std::printf("directory: %s\n", dir.empty() ? "(disabled)" : io::one_line(dir).c_str());
  if (!dir.empty()) {
    const cl_util::ProgramCacheUsage usage = cl_util::program_cache_usage(dir);
    std::printf("programs: %d, %llu bytes", usage.programs,
                static_cast<unsigned long long>(usage.bytes));
    if (usage.bytes >= 1024) std::printf(" (%s)", sys::format_bytes(usage.bytes).c_str());
    std::printf("\n");
    const std::uint64_t max = cl_util::program_cache_max_bytes();
    std::printf("limit: %s (LUCENT_CACHE_MAX_MB; least recently used programs go first)\n",
                max ? sys::format_bytes(max).c_str() : "none");
  }
  say_where_pocl_caches();
}

}  // namespace

CLI::App* add_cache_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "cache",
      "Manage the kernel binary cache (LUCENT_CACHE_DIR, default $XDG_CACHE_HOME/lucent or "
      "~/.cache/lucent; unused on PoCL, whose own cache serves while POCL_KERNEL_CACHE is on). It "
      "keeps its programs under LUCENT_CACHE_MAX_MB MiB (default 256, 0 for no "
      "limit) by removing the least recently used after each write");
  cmd->add_option("action", g_action,
                  "clear: remove every cached program; dir: print the directory; info: the "
                  "directory, the number of cached programs, their size and the limit")
      ->required()
      ->check(CLI::IsMember({"clear", "dir", "info"}));
  return cmd;
}

int run_cache_command() {
  std::string dir = cache_dir_from_environment();
  if (g_action == "dir") {
    std::printf("%s\n", dir.empty() ? "(disabled)" : dir.c_str());
    return 0;
  }
  if (g_action == "info") {
    print_info(dir);
    return 0;
  }
  int n = cl_util::clear_program_cache(dir);
  std::printf("removed %d cached program(s) from %s\n", n,
              dir.empty() ? "(disabled)" : io::one_line(dir).c_str());
  say_where_pocl_caches();
  return 0;
}

}  // namespace lucent::cli
