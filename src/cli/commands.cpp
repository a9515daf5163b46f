#include "cli/commands.hpp"

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "cl/program_cache.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"

namespace lucent::cli {

IntegratorType parse_integrator(const std::string& n) {
  if (std::optional<IntegratorType> t = find_type<IntegratorType>(n)) return *t;
  throw Error("--integrator " + n + ": unknown integrator (expected " +
              type_names<IntegratorType>() + ")");
}

std::vector<std::string> aov_names() {
  std::vector<std::string> out;
  for (const TypeEntry<IntegratorType>& e : TypeList<IntegratorType>::entries)
    if (is_aov(e.value)) out.push_back(e.name);
  out.push_back("variance");
  return out;
}

namespace {
/// A real option's check: "" when ok(value), else "<what>, got <text>" ("must be a number, got
/// <text>" when it is not one). Every real option is refused beyond a float's range, as the
/// scene's numbers are (src/scene/validate.cpp): values that become scene fields (--clamp) would
/// otherwise be blamed on the scene file, and no option means anything that large.
CLI::Validator real_check(std::function<bool(double)> ok, std::string what, std::string name) {
  return CLI::Validator(
      [ok = std::move(ok), what = std::move(what)](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v)) return "must be a number, got " + text;
        if (std::isfinite(v) && std::abs(v) > FLT_MAX)
          return "must fit in a float (magnitude at most 3.4e38), got " + text;
        return ok(v) ? "" : what + ", got " + text;
      },
      std::move(name));
}
}  // namespace

CLI::Validator real_range(double lo, double hi) {
  char what[96];
  std::snprintf(what, sizeof what, "must be in [%g, %g]", lo, hi);
  return real_check([lo, hi](double v) { return v >= lo && v <= hi; }, what, "REAL");
}

CLI::Validator seconds_limit() {
  static_assert(limits::kMaxSeconds == 1e7, "the message says (0, 1e7]");
  return real_check([](double v) { return v > 0 && v <= limits::kMaxSeconds; },
                    "must be in (0, 1e7] seconds", "SECONDS");
}

CLI::Validator positive_real() {
  return real_check([](double v) { return v > 0; }, "must be a positive number", "POSITIVE");
}

CLI::Validator non_negative_real() {
  return real_check([](double v) { return v >= 0; }, "must be 0 or more", "NONNEGATIVE");
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
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
// cmd_merge.cpp
CLI::App* add_merge_command(CLI::App& app);
int run_merge_command();

void register_extra_commands(CLI::App& app) {
  add_compare_command(app);
  add_info_command(app);
  add_cache_command(app);
  add_converge_command(app);
  add_merge_command(app);
}

int run_extra_commands(CLI::App& app) {
  if (app.got_subcommand("compare")) return run_compare_command();
  if (app.got_subcommand("info")) return run_info_command();
  if (app.got_subcommand("cache")) return run_cache_command();
  if (app.got_subcommand("converge")) return run_converge_command();
  if (app.got_subcommand("merge")) return run_merge_command();
  return 0;
}

}  // namespace lucent::cli
