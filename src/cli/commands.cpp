#include "cli/commands.hpp"

#include <functional>
#include <vector>

#include "lucent/error.hpp"

namespace lucent::cli {

IntegratorType parse_integrator(const std::string& n) {
  if (n == "path") return IntegratorType::Path;
  if (n == "whitted") return IntegratorType::Whitted;
  if (n == "direct") return IntegratorType::Direct;
  if (n == "albedo") return IntegratorType::Albedo;
  if (n == "normal") return IntegratorType::Normal;
  if (n == "depth") return IntegratorType::Depth;
  if (n == "ao") return IntegratorType::Ao;
  throw Error("--integrator " + n +
              ": unknown integrator (expected path, whitted, direct, albedo, normal, depth, ao)");
}

void register_extra_commands(CLI::App&) {}

int run_extra_commands(CLI::App&) { return 0; }

}  // namespace lucent::cli
