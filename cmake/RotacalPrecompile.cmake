# SPDX-License-Identifier: BSD-3-Clause
# Precompiled headers: the standard library, Eigen and Ceres' Jet, parsed once per target
# instead of once per translation unit (README, "Build time"). Only external headers, which
# change with the toolchain and not with rotacal's sources, and never nlohmann/json: the 8 files
# that read or write JSON parse it themselves: with it in the precompiled header a file that does
# not use it took longer (ballbar/compensate.cpp 1.2 -> 1.9 CPU-s; loading costs too).
# PRIVATE: the installed targets carry no precompiled header to consumers.
option(ROTACAL_PCH "Precompile the standard library, Eigen and Ceres Jet headers" ON)

set(ROTACAL_PCH_HEADERS
    <algorithm> <array> <cmath> <cstdint> <functional> <limits> <map> <memory> <optional>
    <random> <set> <sstream> <string> <vector> <Eigen/Dense> <ceres/jet.h>
    # Declarations only: Eigen templates compiled once, in src/core/eigen_instances.cpp.
    "${PROJECT_SOURCE_DIR}/src/core/eigen_instances.hpp")

# ccache caches files compiled with a precompiled header only with this sloppiness (its manual,
# "Precompiled headers"); it is set for rotacal's compiles alone, through the launcher (it
# replaces a sloppiness of the user's ccache configuration for these compiles).
function(rotacal_pch_ccache target)
  get_target_property(launcher ${target} CXX_COMPILER_LAUNCHER)
  if(launcher MATCHES "ccache")
    set_target_properties(${target} PROPERTIES CXX_COMPILER_LAUNCHER
      "${CMAKE_COMMAND};-E;env;CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime;${launcher}")
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")  # ccache's preprocessor mode needs it with GCC
      target_compile_options(${target} PRIVATE -fpch-preprocess)
    endif()
  endif()
endfunction()

# rotacal_precompile(target [HEADERS h...]): the list above plus the target's own headers.
function(rotacal_precompile target)
  if(NOT ROTACAL_PCH)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "HEADERS" ${ARGN})
  target_precompile_headers(${target} PRIVATE ${ROTACAL_PCH_HEADERS} ${ARG_HEADERS})
  rotacal_pch_ccache(${target})
endfunction()
