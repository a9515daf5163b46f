// lucent: the command-line front end. A thin layer over the library; every failure ends with one
// line on stderr ("lucent: error: ...") and a non-zero exit status. Subcommands live in
// cmd_*.cpp.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/option_checks.hpp"
#include "core/file_io.hpp"
#include "core/text.hpp"
#include "lucent/lucent.hpp"

namespace {

using lucent::io::one_line;

std::string format_bytes(std::uint64_t b) {
  char buf[32];
  double g = double(b) / (1024.0 * 1024.0 * 1024.0);
  if (g >= 1)
    std::snprintf(buf, sizeof buf, "%.1f GiB", g);
  else
    std::snprintf(buf, sizeof buf, "%.0f MiB", double(b) / (1024.0 * 1024.0));
  return buf;
}

int cmd_devices() {
  auto devices = lucent::list_devices();
  // columns as wide as their longest entry (PoCL's 49-character device name shifted every column
  // after it)
  int platform_width = 28, device_width = 40;
  for (const auto& d : devices) {
    platform_width = std::max(platform_width, static_cast<int>(d.platform.size()));
    device_width = std::max(device_width, static_cast<int>(d.name.size()));
  }
  std::printf("%-3s %-*s %-*s %-5s %4s %10s  %-22s %s\n", "#", platform_width, "platform",
              device_width, "device", "type", "CUs", "memory", "OpenCL C", "fp64");
  for (const auto& d : devices)
    std::printf("%-3d %-*s %-*s %-5s %4u %10s  %-22s %s\n", d.index, platform_width,
                d.platform.c_str(), device_width, d.name.c_str(), d.type.c_str(), d.compute_units,
                format_bytes(d.global_memory).c_str(), d.opencl_c_version.c_str(),
                d.fp64 ? "yes" : "no");
  return 0;
}

/// The usage error of an option value that CLI11 took but no user means
/// (lucent::cli::refused_value), printed, or false.
bool refused_option_value(const CLI::App& app) {
  const std::string bad = lucent::cli::refused_value(app);
  if (bad.empty()) return false;
  std::fprintf(stderr, "lucent: error: %s (see lucent --help)\n", one_line(bad).c_str());
  return true;
}

/// `status`, or 1 when what went to standard output (a table, a comparison, --help) could not be
/// written (a full disk, a closed descriptor): one error line then.
/// `earlier`: the errno of a write that already failed (std::cout flushed by std::endl).
int stdout_written(int status, int earlier = 0) {
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int err = errno ? errno : earlier;
    std::fprintf(stderr, "lucent: error: standard output: cannot write (%s)\n",
                 err ? std::strerror(err) : "write error");
    return status == 0 ? 1 : status;
  }
  return status;
}

/// Prints --help or --version (CLI11 writes it to std::cout) and checks that it was written.
int help_written(const CLI::App& app, const CLI::Error& e) {
  errno = 0;
  const int status = app.exit(e);
  return stdout_written(status, std::ferror(stdout) ? errno : 0);
}

}  // namespace

int main(int argc, char** argv) {
  lucent::io::hold_standard_descriptors();  // (`2>&-`: a lock file became stderr)
  // a file size limit (ulimit -f) must end in an error naming the file, not in a kill
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"lucent: a physically based OpenCL path tracer", "lucent"};
  app.set_version_flag("--version", std::string("lucent ") + lucent::kVersion);
  app.require_subcommand(1);

  CLI::App* render = lucent::cli::add_render_command(app);
  CLI::App* devices = app.add_subcommand("devices", "List OpenCL devices");

  lucent::cli::register_extra_commands(app);

  if (const std::string bad = lucent::cli::empty_list_item(app, argc, argv); !bad.empty()) {
    std::fprintf(stderr,
                 "lucent: error: %s: an empty item in a comma-separated list (see lucent --help)\n",
                 one_line(bad).c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return help_written(app, e);  // (`lucent --help >/dev/full` said nothing, exit 0)
  } catch (const CLI::CallForAllHelp& e) {
    return help_written(app, e);
  } catch (const CLI::CallForVersion& e) {
    return help_written(app, e);
  } catch (const CLI::ParseError& e) {
    if (refused_option_value(app)) return 2;  // before CLI11's range text
    std::string msg = e.what();
    // CLI11 reports a missing argument before an unexpected one: name the unknown option first.
    // A word after "--" is an argument, not an option: `render s.json -- -o a.png` said "unknown
    // option -o", and `render -o a.png -- s.json --spp 1` "unknown option --".
    const std::vector<std::string> extras = app.remaining(true);
    // (a word given after "--" more often than before it: a piece of combined short flags, "-Z"
    // of "-qZ", is in argv in neither place, and is an unknown option)
    char** const dashes = std::find_if(argv + 1, argv + argc,
                                       [](const char* w) { return std::strcmp(w, "--") == 0; });
    // (and a known option left over: given before "--", it would have been read: `-q -- -q`)
    auto given = [](char** first, char** last, const std::string& word) {
      return std::count_if(first, last, [&](const char* w) { return word == w; });
    };
    auto known = [&app](const std::string& word) {
      if (app.get_option_no_throw(word)) return true;
      for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        if (sub->get_option_no_throw(word)) return true;
      return false;
    };
    for (const std::string& extra : extras) {
      if (extra == "--" || extra.size() < 2 || extra[0] != '-') continue;
      if (dashes != argv + argc && given(dashes + 1, argv + argc, extra) > 0 &&
          (known(extra) || given(argv + 1, dashes, extra) == 0)) {
        msg = "unexpected argument " + extra + " after -- (the words after -- are arguments)";
      } else {
        msg = "unknown option " + extra;
        if (extra.find_first_of("./") != std::string::npos)  // a file name, most likely
          msg += " (a file whose name starts with '-' can be given as ./" + extra + ")";
      }
      break;
    }
    // a word that names no command: CLI11 says "A subcommand is required"
    if (app.get_subcommands().empty() && !extras.empty() && !extras[0].empty() &&
        extras[0][0] != '-') {
      std::string names;
      for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        names += (names.empty() ? "" : ", ") + sub->get_name();
      msg = "unknown command " + extras[0] + " (expected one of: " + names + ")";
    }
    for (auto& c : msg)
      if (c == '\n') c = ' ';
    std::fprintf(stderr, "lucent: error: %s (see lucent --help)\n", one_line(msg).c_str());
    return 2;
  }
  if (refused_option_value(app)) return 2;

  int status = 1;
  try {
    if (*render)
      status = lucent::cli::run_render_command();
    else if (*devices)
      status = cmd_devices();
    else
      status = lucent::cli::run_extra_commands(app);
  } catch (const lucent::Error& e) {
    if (!e.details().empty()) std::fprintf(stderr, "%s\n", e.details().c_str());
    std::fprintf(stderr, "lucent: error: %s\n", one_line(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    // name what was being done: the scene, or the command (compare, merge, ...)
    std::string doing = "lucent";
    for (const CLI::App* sub : app.get_subcommands()) doing += " " + sub->get_name();
    std::fprintf(stderr, "lucent: error: out of memory (%s)\n",
                 *render ? ("rendering " + one_line(lucent::cli::render_scene())).c_str()
                         : ("in " + doing).c_str());
    return 1;
  } catch (const std::exception& e) {
    // not a lucent::Error (a limit of the standard library): name what was being done
    std::fprintf(stderr, "lucent: error: %s: %s\n",
                 *render ? one_line(lucent::cli::render_scene()).c_str() : "lucent",
                 one_line(e.what()).c_str());
    return 1;
  }
  return stdout_written(status);
}
