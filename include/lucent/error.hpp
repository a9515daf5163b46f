#pragma once
#include <stdexcept>
#include <string>

namespace lucent {

/// Every failure lucent reports: one line naming the file, the place in it and what is wrong,
/// or the OpenCL call and the error's name (`clBuildProgram: CL_BUILD_PROGRAM_FAILURE`).
/// Some carry details that explain the line (a kernel's build log), to be shown before it.
/// Control characters in the message (from a user's string: a JSON key, a material's or a file's
/// name, a device selector) are escaped as the command line shows them (\n, \t, \x1b, \0...):
/// what() is one line (a name with a newline made two), and a NUL no longer ends its C string.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(shown(message)) {}
  Error(const std::string& message, std::string details)
      : std::runtime_error(shown(message)), details_(std::move(details)) {}
  /// Several lines that explain the error (empty for most errors).
  const std::string& details() const noexcept { return details_; }

 private:
  static std::string shown(const std::string& message);
  std::string details_;
};

}  // namespace lucent
