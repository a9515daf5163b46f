# The installed Python module imports from the install prefix and renders (check_python.py), run
# by the interpreter it was built for. Included by run_package_test.cmake (release builds) after its
# install; run alone (cmake -P) by the sanitizer build's python.installed_module, which CI runs in
# place of the release build's module (scripts/test.sh), with INSTALL=ON to install BINARY_DIR
# into WORK_DIR/prefix first and ASAN_RUNTIME / STDCXX preloaded into python, as for the module's
# pytest entries (python/CMakeLists.txt).
if(INSTALL)
  file(REMOVE_RECURSE ${WORK_DIR})
  execute_process(COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${WORK_DIR}/prefix
                  RESULT_VARIABLE rc OUTPUT_QUIET)
  if(rc)
    message(FATAL_ERROR "install failed: ${rc}")
  endif()
endif()
set(module_dir ${WORK_DIR}/prefix/${PYTHON_INSTALL_DIR})
file(GLOB module ${module_dir}/lucent*.so)
if(NOT module)
  message(FATAL_ERROR "the Python module is not installed in ${module_dir}")
endif()
set(preload)
if(ASAN_RUNTIME)
  set(preload "LD_PRELOAD=${ASAN_RUNTIME} ${STDCXX}" "ASAN_OPTIONS=detect_leaks=0:use_sigaltstack=0")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${module_dir} ${preload}
                        ${PYTHON_EXECUTABLE} ${SOURCE_DIR}/tests/package/check_python.py
                        ${WORK_DIR}/prefix ${VERSION}
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "importing the installed Python module failed: ${rc}")
endif()
