#pragma once
// Helpers shared by the tests: running the CLI, temporary files, rendering small scenes.
#include <string>

#include "lucent/lucent.hpp"

namespace lucent::test {

struct CommandResult {
  int status = -1;  ///< exit status (128 + signal when killed)
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs the lucent CLI with `args` (a shell-quoted string) and optional extra environment
/// assignments placed before the command (e.g. "LUCENT_DEVICE=foo").
CommandResult run_cli(const std::string& args, const std::string& env = "");

/// A fresh directory under the build tree, removed at the end of the test program.
std::string temp_dir();

/// Writes `text` to `path`.
void write_file(const std::string& path, const std::string& text);

/// Path of a file under the source tree.
std::string source_path(const std::string& rel);

/// ../shared/assets/<rel> beside the project, or "" when ../shared is absent.
std::string shared_asset(const std::string& rel);

/// Renders a JSON scene held in memory with `spp` samples per pixel.
RenderResult render_json(const std::string& json, int spp);

/// Number of lines in `s` that are not empty.
int count_lines(const std::string& s);

}  // namespace lucent::test
