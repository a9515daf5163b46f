// `lucent cache clear|dir`: the on-disk cache of built kernel programs (src/cl/program_cache.hpp).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "cl/context.hpp"
#include "cl/program_cache.hpp"
#include "cli/commands.hpp"
#include "lucent/error.hpp"

namespace lucent::cli {

namespace {
std::string g_action;
}

CLI::App* add_cache_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "cache",
      "Manage the kernel binary cache (LUCENT_CACHE_DIR, default $XDG_CACHE_HOME/lucent or "
      "~/.cache/lucent; unused on PoCL while POCL_KERNEL_CACHE is on, PoCL's own cache serving "
      "instead)");
  cmd->add_option("action", g_action,
                  "clear: remove every cached program; dir: print the directory")
      ->required()
      ->check(CLI::IsMember({"clear", "dir"}));
  return cmd;
}

int run_cache_command() {
  std::string dir = cache_dir_from_environment();
  if (g_action == "dir") {
    std::printf("%s\n", dir.empty() ? "(disabled)" : dir.c_str());
    return 0;
  }
  int n = cl_util::clear_program_cache(dir);
  std::printf("removed %d cached program(s) from %s\n", n,
              dir.empty() ? "(disabled)" : dir.c_str());
  // on PoCL, sessions leave caching to PoCL's own cache (cl/program_cache.hpp): say where it is
  try {
    for (const cl_util::Device& d : cl_util::enumerate_devices())
      if (!cl_util::driver_program_cache(d).empty()) {
        // (the directory PoCL uses: it said "default ~/.cache/pocl/kcache" whatever
        // XDG_CACHE_HOME chose)
        std::printf(
            "%s: kernels are cached by PoCL in %s (POCL_CACHE_DIR), not here; remove that "
            "directory to rebuild them from source\n",
            d.info.name.c_str(), one_line(cl_util::pocl_cache_dir()).c_str());
        break;
      }
  } catch (const Error&) {
    // no OpenCL platform: nothing more to say
  }
  return 0;
}

}  // namespace lucent::cli
