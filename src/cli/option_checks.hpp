#pragma once
// Option values as a user means them, for `lucent` and `lucent-mpi` alike. CLI11 reads an
// integer with a leading zero as octal and takes 0x and 0b prefixes: `--spp 010` rendered 8
// samples per pixel without a word, and `--spp 0b11` was refused as "not in range 1 to 16777216".
// An empty string was taken as no value: `--checkpoint ''` rendered without checkpoints, exit 0.
#include <CLI/CLI.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace lucent::cli {

/// A name or a path (an integrator, a device, a checkpoint, an output): not empty.
inline CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& text) -> std::string { return text.empty() ? "must not be empty" : ""; }, "");
}

/// What an integer option's value must be, for the error line.
inline constexpr const char kDecimalIntegers[] =
    "integers are plain decimal digits, without a leading zero or a base prefix (0x, 0b)";

/// Whether `text` is an integer in plain decimal: an optional '-', then 0 or digits that do not
/// start with 0.
inline bool plain_decimal(const std::string& text) {
  const size_t start = !text.empty() && text[0] == '-' ? 1 : 0;
  if (text.size() == start || text.find_first_not_of("0123456789", start) != std::string::npos)
    return false;
  return text[start] != '0' || text.size() == start + 1;
}

/// The first value given to an option of `app` or its subcommands whose CLI11 type name
/// (get_type_name(): the type, then the validators' descriptions) `typed` accepts, that `bad`
/// finds wrong, as "--name value" ("--name ''" for an empty one; "" when none). Each element of a
/// comma-separated list is a value; an empty result is one empty value.
template <class Typed, class Bad>
std::string first_bad_value(const CLI::App& app, Typed typed, Bad bad) {
  std::vector<const CLI::App*> apps{&app};
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    apps.push_back(sub);
  for (const CLI::App* a : apps)
    for (const CLI::Option* o : a->get_options()) {
      if (!typed(o->get_type_name())) continue;
      for (const std::string& all : o->results()) {
        std::string value;
        std::istringstream items(all);
        bool any = false;
        while (std::getline(items, value, ',') || (!any && all.empty())) {
          any = true;
          if (bad(value)) return o->get_name() + " " + (value.empty() ? "''" : value);
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
      [](const std::string& value) { return !plain_decimal(value); });
}

}  // namespace lucent::cli
