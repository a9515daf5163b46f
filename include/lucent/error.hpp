#pragma once
#include <stdexcept>
#include <string>

namespace lucent {

/// Every failure lucent reports: one line naming the file, the place in it and what is wrong,
/// or the OpenCL call and the error's name (`clBuildProgram: CL_BUILD_PROGRAM_FAILURE`).
/// Some carry details that explain the line (a kernel's build log), to be shown before it.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const std::string& message, std::string details)
      : std::runtime_error(message), details_(std::move(details)) {}
  /// Several lines that explain the error (empty for most errors).
  const std::string& details() const noexcept { return details_; }

 private:
  std::string details_;
};

}  // namespace lucent
