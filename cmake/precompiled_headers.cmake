# Precompiled headers: Eigen (every core header includes Eigen/Geometry), GoogleTest and CLI11
# are parsed once per kind of target instead of once per source file. Compiling is most of the
# test command's time (docs/contributing.md, "Build time").
#
#   posefair_precompile(<target> <kind>)
#     kind: core     Eigen and the standard headers the libraries use
#           test     core's + GoogleTest and GoogleMock, for every test program
#           cli      core's + CLI11, for the command-line programs
# Each kind's header is built once per build tree, by a target of its own (posefair_pch_<kind>)
# that has no compile definitions of the project's: GCC refuses a precompiled header when a
# macro it was built with is missing, but not for macros the header never mentions, so every
# target of that kind can reuse it (REUSE_FROM). -Winvalid-pch (added by CMake) under -Werror
# turns a refused header into a build error rather than a silent slow build.
option(POSEFAIR_PCH "Precompile Eigen, GoogleTest and CLI11 headers" ON)

set(_posefair_pch_headers_core
  <algorithm> <array> <cmath> <cstdint> <cstring> <limits> <memory> <optional> <span>
  <stdexcept> <string> <string_view> <utility> <vector>
  <Eigen/Core> <Eigen/Geometry>)

function(posefair_precompile target kind)
  if(NOT POSEFAIR_PCH)
    return()
  endif()
  if(kind STREQUAL "core")
    set(libs Eigen3::Eigen)
    set(headers ${_posefair_pch_headers_core})
  elseif(kind STREQUAL "test")
    set(libs Eigen3::Eigen GTest::gtest GTest::gmock)
    set(headers ${_posefair_pch_headers_core} <gtest/gtest.h> <gmock/gmock.h>)
  elseif(kind STREQUAL "cli")
    set(libs Eigen3::Eigen CLI11::CLI11)
    set(headers ${_posefair_pch_headers_core} <CLI/CLI.hpp>)
  else()
    message(FATAL_ERROR "posefair_precompile: unknown kind '${kind}'")
  endif()
  set(owner posefair_pch_${kind})
  if(NOT TARGET ${owner})
    add_library(${owner} STATIC ${PROJECT_SOURCE_DIR}/cmake/precompiled_headers.cpp)
    # posefair_warnings: -Wpedantic changes predefined macros (__cpp_runtime_arrays).
    target_link_libraries(${owner} PRIVATE ${libs} posefair_warnings)
    if(kind STREQUAL "test")
      target_compile_options(${owner} PRIVATE ${POSEFAIR_TEST_OPTIMIZATION})
    endif()
    target_precompile_headers(${owner} PRIVATE ${headers})
  endif()
  # The headers' include paths and definitions (GTEST_HAS_PTHREAD), whatever the target links.
  foreach(lib ${libs})
    target_include_directories(${target} SYSTEM PRIVATE $<TARGET_PROPERTY:${lib},INTERFACE_INCLUDE_DIRECTORIES>)
    target_compile_definitions(${target} PRIVATE $<TARGET_PROPERTY:${lib},INTERFACE_COMPILE_DEFINITIONS>)
  endforeach()
  target_precompile_headers(${target} REUSE_FROM ${owner})
endfunction()
