#pragma once
#include <stdexcept>
#include <string>

namespace lucent {

/// Every failure lucent reports: one line naming the file, the place in it and what is wrong,
/// or the OpenCL call and the error's name (`clBuildProgram: CL_BUILD_PROGRAM_FAILURE`).
/// Some carry details that explain the line (a kernel's build log), to be shown before it.
/// A NUL character in the message (from a user's string: a device selector, a file's attribute)
/// is shown as \0: what() is a C string, which ended there and cut the rest of the line off.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(shown(message)) {}
  Error(const std::string& message, std::string details)
      : std::runtime_error(shown(message)), details_(std::move(details)) {}
  /// Several lines that explain the error (empty for most errors).
  const std::string& details() const noexcept { return details_; }

 private:
  static std::string shown(std::string message) {
    for (std::size_t at = message.find('\0'); at != std::string::npos;
         at = message.find('\0', at + 2))
      message.replace(at, 1, "\\0");
    return message;
  }
  std::string details_;
};

}  // namespace lucent
