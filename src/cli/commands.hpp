#pragma once
// Subcommands beyond render and devices live in their own files and register here.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lucent/scene.hpp"

namespace lucent::cli {

/// "path", "whitted", ... -> IntegratorType; throws lucent::Error on an unknown name.
IntegratorType parse_integrator(const std::string& name);

/// The names --aov accepts: the registry's AOVs (albedo, normal, ...), then "variance".
std::vector<std::string> aov_names();

/// "a, b, c".
std::string joined(const std::vector<std::string>& names);

/// Adds the extra subcommands (info, ...) to `app`.
void register_extra_commands(CLI::App& app);

/// Runs whichever extra subcommand was parsed; returns the exit status.
int run_extra_commands(CLI::App& app);

}  // namespace lucent::cli
