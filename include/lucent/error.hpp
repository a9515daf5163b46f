#pragma once
#include <stdexcept>
#include <string>

namespace lucent {

/// Every failure lucent reports: one line naming the file, the place in it and what is wrong,
/// or the OpenCL call and the error's name (`clBuildProgram: CL_BUILD_PROGRAM_FAILURE`).
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace lucent
