#pragma once
// The one place that includes the OpenCL C++ bindings, with lucent's settings.
#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#define CL_HPP_ENABLE_EXCEPTIONS
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
#include <CL/opencl.hpp>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <string>

namespace lucent::cl_util {

/// "CL_BUILD_PROGRAM_FAILURE" for -11, "CL_UNKNOWN_ERROR(<code>)" for codes it does not know.
std::string error_name(cl_int code);

/// "clBuildProgram: CL_BUILD_PROGRAM_FAILURE" from a cl::Error.
std::string describe(const cl::Error& e);

}  // namespace lucent::cl_util
