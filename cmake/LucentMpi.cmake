# lucent-mpi (src/mpi/): one render split over MPI ranks. LUCENT_MPI: AUTO (default) builds it
# when an MPI implementation is found (Debian: libopenmpi-dev openmpi-bin), ON requires one, OFF
# skips it.
set(LUCENT_MPI AUTO CACHE STRING "Build lucent-mpi: AUTO (when MPI is found), ON or OFF")
set_property(CACHE LUCENT_MPI PROPERTY STRINGS AUTO ON OFF)
# CMake's other spellings of a boolean mean ON and OFF too (-DLUCENT_MPI=NO was AUTO, and built
# lucent-mpi; =1 or =TRUE was AUTO, and skipped it silently without MPI); anything else is refused
string(TOUPPER "${LUCENT_MPI}" _lucent_mpi)
if(_lucent_mpi MATCHES "^(ON|1|YES|Y|TRUE)$")
  set(_lucent_mpi ON)
elseif(_lucent_mpi MATCHES "^(OFF|0|NO|N|FALSE)$")
  set(_lucent_mpi OFF)
elseif(NOT _lucent_mpi STREQUAL "AUTO")
  message(FATAL_ERROR "lucent: LUCENT_MPI is '${LUCENT_MPI}': AUTO, ON or OFF")
endif()
if(NOT _lucent_mpi STREQUAL "OFF")
  if(_lucent_mpi STREQUAL "ON")
    find_package(MPI REQUIRED COMPONENTS C)
  else()
    find_package(MPI QUIET COMPONENTS C)
  endif()
  if(MPI_C_FOUND)
    # the checkpoints are `lucent render --checkpoint`'s (src/cli/checkpoint.cpp, compiled again:
    # the CLI's code is not in the library)
    add_executable(lucent_mpi ${CMAKE_CURRENT_SOURCE_DIR}/src/mpi/lucent_mpi.cpp
                              ${CMAKE_CURRENT_SOURCE_DIR}/src/cli/checkpoint.cpp)
    lucent_glue_target(lucent_mpi)
    # it parses arguments and passes parts (the library does the work): -O1 compiles it in 6.5 s
    # instead of 10.5 s at -O3 (CLI11's inline functions, as for the CLI above)
    if(NOT LUCENT_SANITIZE)
      target_compile_options(lucent_mpi PRIVATE $<$<NOT:$<CONFIG:Debug>>:-O1>)
    endif()
    set_target_properties(lucent_mpi PROPERTIES OUTPUT_NAME lucent-mpi)
    target_compile_options(lucent_mpi PRIVATE -Wall -Wextra)
    # the C API only: no deprecated C++ bindings (their symbols are in another library)
    target_compile_definitions(lucent_mpi PRIVATE OMPI_SKIP_MPICXX=1 MPICH_SKIP_MPICXX=1)
    # OpenCL too, as for the CLI: it includes cl/context.hpp, and a shared lucent does not pass
    # its private link on (-DBUILD_SHARED_LIBS=ON failed to link lucent-mpi)
    target_link_libraries(lucent_mpi PRIVATE lucent CLI11::CLI11 MPI::MPI_C OpenCL::OpenCL)
    target_include_directories(lucent_mpi PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src
                                                  ${CMAKE_CURRENT_SOURCE_DIR}/kernels)
    install(TARGETS lucent_mpi RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    lucent_install_rpath(lucent_mpi ${CMAKE_INSTALL_BINDIR})
    message(STATUS "lucent-mpi: building against MPI ${MPI_C_VERSION} (${MPIEXEC_EXECUTABLE})")
  else()
    message(STATUS "lucent-mpi: no MPI found, not built (Debian: apt-get install libopenmpi-dev "
                   "openmpi-bin; -DLUCENT_MPI=OFF to skip the search)")
  endif()
endif()
