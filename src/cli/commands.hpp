#pragma once
// Subcommands beyond render and devices live in their own files and register here.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "lucent/render.hpp"
#include "lucent/scene.hpp"
#include "lucent/session.hpp"

namespace lucent::cli {

/// "path", "whitted", ... -> IntegratorType; throws lucent::Error on an unknown name.
IntegratorType parse_integrator(const std::string& name);

/// The command's defaults for a render: device, kernel directory and cache directory from
/// LUCENT_DEVICE, LUCENT_KERNEL_DIR and LUCENT_CACHE_DIR
/// (lucent::SessionOptions::from_environment).
RenderOptions render_options_from_environment();

/// Session options for a render: the environment's defaults, `device` (from --device) when not
/// empty. Checks the device selector first, so that an unknown one is reported as the
/// command's user gave it ("--device 'x': ..." or "LUCENT_DEVICE 'x': ...").
SessionOptions session_options(const std::string& device);

/// The kernel binary cache directory the command uses ("" when disabled: LUCENT_CACHE_DIR=off).
std::string cache_dir_from_environment();
/// The names --aov accepts: the registry's AOVs (albedo, normal, ...), then "variance".
std::vector<std::string> aov_names();

/// "a, b, c".
std::string joined(const std::vector<std::string>& names);

/// `lucent render` (cmd_render.cpp): registers the subcommand, runs it once parsed; the scene
/// path given, for messages.
CLI::App* add_render_command(CLI::App& app);
int run_render_command();
const std::string& render_scene();

/// Adds the extra subcommands (info, ...) to `app`.
void register_extra_commands(CLI::App& app);

/// Runs whichever extra subcommand was parsed; returns the exit status.
int run_extra_commands(CLI::App& app);

}  // namespace lucent::cli
