# Installs the already built lucent into WORK_DIR/prefix, then configures, builds and runs a
# consumer project that uses find_package(lucent).
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "install failed: ${rc}")
endif()
# the installed programs run from the prefix (a shared lucent: they find liblucent there) and
# report the package's version
foreach(program lucent lucent-mpi)
  if(program STREQUAL "lucent" OR EXISTS ${WORK_DIR}/prefix/bin/${program})
    execute_process(COMMAND ${WORK_DIR}/prefix/bin/${program} --version WORKING_DIRECTORY ${WORK_DIR}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                    OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(rc OR NOT out STREQUAL "${program} ${VERSION}")
      message(FATAL_ERROR "the installed ${program} --version: exit ${rc}, '${out}' ${err} (expected "
                          "'${program} ${VERSION}')")
    endif()
  endif()
endforeach()

# The version file: before 1.0 a minor version may change the API, so a request for another
# minor version is refused (SameMajorVersion took 0.1.0 for find_package(lucent 0.0.1)).
file(GLOB version_file ${WORK_DIR}/prefix/lib*/cmake/lucent/lucentConfigVersion.cmake)
string(REPLACE "." ";" parts ${VERSION})
list(GET parts 0 major)
list(GET parts 1 minor)
math(EXPR next_minor "${minor} + 1")
set(checks "${major}.${minor}=TRUE" "${major}.${minor}.0=TRUE" "${major}.${next_minor}=FALSE")
if(major EQUAL 0 AND minor GREATER 0)
  math(EXPR previous_minor "${minor} - 1")
  list(APPEND checks "0.${previous_minor}.1=FALSE")
endif()
function(package_version_compatible wanted out)
  string(REPLACE "." ";" w ${wanted})
  list(LENGTH w PACKAGE_FIND_VERSION_COUNT)
  list(APPEND w 0 0)
  list(GET w 0 PACKAGE_FIND_VERSION_MAJOR)
  list(GET w 1 PACKAGE_FIND_VERSION_MINOR)
  list(GET w 2 PACKAGE_FIND_VERSION_PATCH)
  set(PACKAGE_FIND_VERSION ${wanted})
  include(${version_file})
  set(${out} ${PACKAGE_VERSION_COMPATIBLE} PARENT_SCOPE)
endfunction()
foreach(check ${checks})
  string(REPLACE "=" ";" check ${check})
  list(GET check 0 wanted)
  list(GET check 1 expected)
  package_version_compatible(${wanted} got)
  if(NOT "${got}" STREQUAL expected)
    message(FATAL_ERROR "the installed lucent ${VERSION} answers ${got} to find_package(lucent "
                        "${wanted}), expected ${expected} (${version_file})")
  endif()
endforeach()

# A shared lucent links its private dependencies itself: its consumer needs GLM's development
# files alone (the config asked for OpenCL's, nlohmann-json's, tinyobjloader's and tinyexr's)
file(GLOB shared_library ${WORK_DIR}/prefix/lib*/liblucent.so)
set(without_private_dependencies)
if(shared_library)
  foreach(package OpenCL nlohmann_json tinyobjloader tinyexr)
    list(APPEND without_private_dependencies -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
  endforeach()
endif()

# The consumer is the README's CMake lines: it sets no C++ standard of its own. Configured at
# C++14, the default of clang 14 (GCC 12's is C++17): lucent::lucent must bring C++17 itself.
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/consumer -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
                        -DCMAKE_CXX_STANDARD=14 ${without_private_dependencies}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed: ${rc}")
endif()
# run from an unrelated directory: kernels are embedded
execute_process(COMMAND ${WORK_DIR}/build/consumer WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the consumer failed: ${rc}")
endif()

# a consumer that makes GLM's types aligned (a dvec3 of 32 bytes) cannot build: the library
# would misread its structs (a camera's up read as zero), which it did without a word
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/consumer
                        -B ${WORK_DIR}/build-aligned -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
                        "-DCMAKE_CXX_FLAGS=-DGLM_FORCE_DEFAULT_ALIGNED_GENTYPES -DGLM_FORCE_INTRINSICS"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "configuring the aligned-GLM consumer failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build-aligned RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc OR NOT "${out}${err}" MATCHES "lucent's structs need GLM's default layout")
  message(FATAL_ERROR "a consumer with GLM_FORCE_DEFAULT_ALIGNED_GENTYPES built (exit ${rc}), or "
                      "failed for another reason: ${out}${err}")
endif()

# the Python module, when it was built: installed where PYTHON_INSTALL_DIR says, imported from
# there by the interpreter it was built for
if(PYTHON_EXECUTABLE AND PYTHON_INSTALL_DIR)
  include(${CMAKE_CURRENT_LIST_DIR}/python_module_check.cmake)
endif()
