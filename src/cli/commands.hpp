#pragma once
// Subcommands beyond render and devices live in their own files and register here.
#include <string>

#include <CLI/CLI.hpp>

#include "lucent/scene.hpp"

namespace lucent::cli {

/// "path", "whitted", ... -> IntegratorType; throws lucent::Error on an unknown name.
IntegratorType parse_integrator(const std::string& name);

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
