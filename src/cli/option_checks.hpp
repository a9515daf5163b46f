#pragma once
// Option values as a user means them, for `lucent` and `lucent-mpi` alike. CLI11 reads an
// integer with a leading zero as octal and takes 0x and 0b prefixes: `--spp 010` rendered 8
// samples per pixel without a word, and `--spp 0b11` was refused as "not in range 1 to 16777216".
// An empty string was taken as no value: `--checkpoint ''` rendered without checkpoints, exit 0.
// A real took a hex float (`--time 0x10` ran 16 s) and a leading space; CLI11's range checks
// let NaN through (every comparison with it is false), and a NaN --time would never end a render.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/text.hpp"

namespace lucent::cli {

/// A name or a path (an integrator, a device, a checkpoint, an output): not empty.
inline CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& text) -> std::string { return text.empty() ? "must not be empty" : ""; }, "");
}

/// What an integer option's value must be, for the error line.
inline constexpr const char kDecimalIntegers[] =
    "integers are plain decimal digits, without a leading zero or a base prefix (0x, 0b)";

/// What a real option's value must be, for the error line.
inline constexpr const char kDecimalReals[] =
    "reals are decimal numbers such as 2, 0.5 or 1e-3, without a base prefix (0x) or spaces";

/// The first value given to an option of `app` or its subcommands whose CLI11 type name
/// (get_type_name(): the type, then the validators' descriptions) `typed` accepts, that `bad`
/// finds wrong, as "--name value" (quoted when empty or holding a space: "--name ''"; "" when
/// none). Each element of a comma-separated list is a value, for an option that splits its values
/// (a CLI11 delimiter: `--spp 1,000` was named as "--spp 000"); an empty result is one empty value.
template <class Typed, class Bad>
std::string first_bad_value(const CLI::App& app, Typed typed, Bad bad) {
  std::vector<const CLI::App*> apps{&app};
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    apps.push_back(sub);
  for (const CLI::App* a : apps)
    for (const CLI::Option* o : a->get_options()) {
      if (!typed(o->get_type_name())) continue;
      const char delimiter = o->get_delimiter();
      for (const std::string& all : o->results()) {
        std::vector<std::string> values;
        std::string value;
        std::istringstream items(all);
        if (delimiter == '\0' || all.empty())
          values.push_back(all);
        else
          while (std::getline(items, value, delimiter)) values.push_back(value);
        for (const std::string& v : values)
          if (bad(v)) {
            const bool quote = v.empty() || v.find_first_of(" \t") != std::string::npos;
            return o->get_name() + " " + (quote ? "'" + v + "'" : v);
          }
      }
    }
  return "";
}

/// The first integer option (CLI11's type INT or UINT) given a value that is not plain decimal,
/// as first_bad_value says it. The type is the name's part before the validators' descriptions
/// ("INT:INT in [1 - 16777216]"): a real option checked by CLI::Range(0, 1) shows "FLOAT:INT in
/// [0 - 1]".
inline std::string non_decimal_option(const CLI::App& app) {
  return first_bad_value(
      app,
      [](const std::string& type) {
        const std::string base = type.substr(0, type.find(':'));
        return base == "INT" || base == "UINT";
      },
      [](const std::string& value) { return !io::plain_decimal_integer(value); });
}

/// The first comma-separated list in `argv` given to an option of `app` or its subcommands that
/// splits its values (a CLI11 delimiter) with an empty item, as "--name value" ("" when none):
/// CLI11 drops empty items, so `converge --settings default,,mis` and `--spp-ladder 1,,2` ran
/// without a word. Read from argv, before CLI11 splits the values.
inline std::string empty_list_item(const CLI::App& app, int argc, const char* const* argv) {
  // the options of `app` and of the subcommand argv names (the first word that is one)
  std::vector<const CLI::App*> apps{&app};
  for (int i = 1; i < argc && apps.size() == 1; ++i)
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      if (sub->get_name() == argv[i]) apps.push_back(sub);
  const auto has_empty_item = [](const std::string& value, char d) {
    return !value.empty() && (value.front() == d || value.back() == d ||
                              value.find(std::string(2, d)) != std::string::npos);
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.rfind("--", 0) != 0) continue;
    const size_t eq = arg.find('=');
    const std::string name = arg.substr(0, eq);
    for (const CLI::App* a : apps) {
      const CLI::Option* o = a->get_option_no_throw(name);
      if (!o || o->get_delimiter() == '\0') continue;
      const char d = o->get_delimiter();
      if (eq != std::string::npos && has_empty_item(arg.substr(eq + 1), d))
        return name + " " + arg.substr(eq + 1);
      // the words after it, up to the next option (a list option takes them all)
      for (int k = i + 1; eq == std::string::npos && k < argc && argv[k][0] != '-'; ++k)
        if (has_empty_item(argv[k], d)) return name + " " + argv[k];
      break;
    }
  }
  return "";
}

/// Whether a CLI11 type name (get_type_name()) is a real option's: "FLOAT", or "FLOAT:" and its
/// validators' descriptions.
inline bool real_type(const std::string& type) { return type.substr(0, type.find(':')) == "FLOAT"; }

/// The usage error of the first option value that CLI11 took but no user means, as
/// "--name value: what it must be" ("" when none): an integer that is not plain decimal, a real
/// that is not finite, a real number that is not plain decimal. Checked whether or not the parse
/// failed (with 0b11, CLI11's own range error came first).
inline std::string refused_value(const CLI::App& app) {
  if (std::string bad = non_decimal_option(app); !bad.empty()) return bad + ": " + kDecimalIntegers;
  const std::string not_finite = first_bad_value(app, real_type, [](const std::string& value) {
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    return end != value.c_str() && *end == '\0' && !std::isfinite(v);
  });
  if (!not_finite.empty()) return not_finite + ": must be a finite number";
  // (what strtod reads whole, as CLI11 does: a value that is no number keeps CLI11's message)
  const std::string not_decimal = first_bad_value(app, real_type, [](const std::string& value) {
    char* end = nullptr;
    std::strtod(value.c_str(), &end);
    return end != value.c_str() && *end == '\0' && !io::plain_decimal_real(value);
  });
  if (!not_decimal.empty()) return not_decimal + ": " + kDecimalReals;
  return "";
}

}  // namespace lucent::cli
