# SPDX-License-Identifier: BSD-3-Clause
# One place for warning flags, applied per target (never globally, never forcing a build type).
function(rotacal_set_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                                             -Wnon-virtual-dtor -Wno-unused-parameter)
  endif()
endfunction()
