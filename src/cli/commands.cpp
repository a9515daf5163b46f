#include "cli/commands.hpp"

#include <functional>
#include <vector>

#include "cl/program_cache.hpp"
#include "lucent/error.hpp"
#include "lucent/session.hpp"

namespace lucent::cli {

IntegratorType parse_integrator(const std::string& n) {
  if (n == "path") return IntegratorType::Path;
  if (n == "whitted") return IntegratorType::Whitted;
  if (n == "direct") return IntegratorType::Direct;
  if (n == "albedo") return IntegratorType::Albedo;
  if (n == "normal") return IntegratorType::Normal;
  if (n == "depth") return IntegratorType::Depth;
  if (n == "ao") return IntegratorType::Ao;
  if (n == "primitive") return IntegratorType::Primitive;
  throw Error("--integrator " + n +
              ": unknown integrator (expected path, whitted, direct, albedo, normal, depth, ao, "
              "primitive)");
}

RenderOptions render_options_from_environment() {
  SessionOptions s = SessionOptions::from_environment();
  RenderOptions o;
  o.device = s.device;
  o.kernel_dir = s.kernel_dir;
  o.cache_dir = s.cache_dir;
  return o;
}

SessionOptions session_options(const std::string& device) {
  SessionOptions s = SessionOptions::from_environment();
  std::string origin = "LUCENT_DEVICE";
  if (!device.empty()) {
    s.device = device;
    origin = "--device";
  }
  if (!s.device.empty()) select_devices(s.device, origin);
  return s;
}

std::string cache_dir_from_environment() {
  std::string dir = SessionOptions::from_environment().cache_dir;
  if (dir == "off") return "";
  return dir.empty() ? cl_util::default_program_cache_dir() : dir;
}

// cmd_compare.cpp
CLI::App* add_compare_command(CLI::App& app);
int run_compare_command();
// cmd_info.cpp
CLI::App* add_info_command(CLI::App& app);
int run_info_command();
// cmd_cache.cpp
CLI::App* add_cache_command(CLI::App& app);
int run_cache_command();
// cmd_converge.cpp
CLI::App* add_converge_command(CLI::App& app);
int run_converge_command();

void register_extra_commands(CLI::App& app) {
  add_compare_command(app);
  add_info_command(app);
  add_cache_command(app);
  add_converge_command(app);
}

int run_extra_commands(CLI::App& app) {
  if (app.got_subcommand("compare")) return run_compare_command();
  if (app.got_subcommand("info")) return run_info_command();
  if (app.got_subcommand("cache")) return run_cache_command();
  if (app.got_subcommand("converge")) return run_converge_command();
  return 0;
}

}  // namespace lucent::cli
