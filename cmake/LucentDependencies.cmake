# Every dependency comes from a Debian package. When one is missing, stop with a message that
# names the package to install (scripts/install-deps.sh installs all of them).

function(lucent_require found package what)
  if(NOT ${found})
    message(FATAL_ERROR "lucent: ${what} not found: install the Debian package '${package}' "
                        "(or run scripts/install-deps.sh)")
  endif()
endfunction()

set(THREADS_PREFER_PTHREAD_FLAG ON)
find_package(Threads REQUIRED)

find_package(OpenCL QUIET)
lucent_require(OpenCL_FOUND ocl-icd-opencl-dev "the OpenCL ICD loader (libOpenCL)")

find_path(LUCENT_OPENCL_HPP_DIR CL/opencl.hpp)
lucent_require(LUCENT_OPENCL_HPP_DIR opencl-clhpp-headers "the OpenCL C++ header CL/opencl.hpp")

find_package(glm CONFIG QUIET)
lucent_require(glm_FOUND libglm-dev "GLM")

find_package(nlohmann_json CONFIG QUIET)
lucent_require(nlohmann_json_FOUND nlohmann-json3-dev "nlohmann-json")

find_package(tinyobjloader CONFIG QUIET)
lucent_require(tinyobjloader_FOUND libtinyobjloader-dev "tinyobjloader")

find_package(tinyexr CONFIG QUIET)
lucent_require(tinyexr_FOUND libtinyexr-dev "tinyexr")

find_package(CLI11 CONFIG QUIET)
lucent_require(CLI11_FOUND libcli11-dev "CLI11")

find_path(LUCENT_STB_INCLUDE_DIR stb/stb_image.h)
find_library(LUCENT_STB_LIBRARY stb)
if(LUCENT_STB_INCLUDE_DIR AND LUCENT_STB_LIBRARY)
  set(LUCENT_STB_FOUND ON)
endif()
lucent_require(LUCENT_STB_FOUND libstb-dev "stb (stb_image, stb_image_write)")
if(NOT TARGET lucent_stb)
  add_library(lucent_stb INTERFACE)
  target_include_directories(lucent_stb SYSTEM INTERFACE ${LUCENT_STB_INCLUDE_DIR})
  target_link_libraries(lucent_stb INTERFACE ${LUCENT_STB_LIBRARY})
  install(TARGETS lucent_stb EXPORT lucentTargets)
endif()

if(LUCENT_BUILD_TESTS)
  find_package(GTest CONFIG QUIET)
  if(NOT GTest_FOUND)
    find_package(GTest QUIET)
  endif()
  lucent_require(GTest_FOUND libgtest-dev "GoogleTest")
endif()
