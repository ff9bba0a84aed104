# Precompiled headers: Eigen (every core header includes Eigen/Geometry), GoogleTest and CLI11
# are parsed once per kind of target instead of once per source file. Compiling is most of the
# test command's time (docs/contributing.md, "Build time").
#
#   posefair_precompile(<target> <kind>)
#     kind: core     Eigen and the standard headers the libraries use
#           test     core + GoogleTest and GoogleMock, one PCH reused by every test program
#           cli      core + CLI11, for the command-line programs
# One target per kind owns the precompiled header; the others of that kind reuse it
# (REUSE_FROM), so it is built once per build tree, not once per target.
option(POSEFAIR_PCH "Precompile Eigen, GoogleTest and CLI11 headers" ON)

set(_posefair_pch_core
  <algorithm> <array> <cmath> <cstdint> <cstring> <limits> <memory> <optional> <span>
  <stdexcept> <string> <string_view> <utility> <vector>
  <Eigen/Core> <Eigen/Geometry>)
set(_posefair_pch_test ${_posefair_pch_core} <gtest/gtest.h> <gmock/gmock.h>)
set(_posefair_pch_cli ${_posefair_pch_core} <CLI/CLI.hpp>)

function(posefair_precompile target kind)
  if(NOT POSEFAIR_PCH)
    return()
  endif()
  get_property(owner GLOBAL PROPERTY POSEFAIR_PCH_OWNER_${kind})
  if(owner)
    target_precompile_headers(${target} REUSE_FROM ${owner})
  else()
    target_precompile_headers(${target} PRIVATE ${_posefair_pch_${kind}})
    set_property(GLOBAL PROPERTY POSEFAIR_PCH_OWNER_${kind} ${target})
  endif()
endfunction()
