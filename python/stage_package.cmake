# SPDX-License-Identifier: BSD-3-Clause
# Stage the rotacal Python package for a plain CMake build (cmake -P, run by rotacal_py_stage):
# every .py and .pyi under SRC, subpackages included, py.typed and data/*.json, copied to DST
# with their folders; staged sources that no longer exist in SRC are removed (a module turned
# into a package, e.g. cli.py into cli/, must not be left beside it). The extension module
# built into DST is not touched.
cmake_minimum_required(VERSION 3.18)
if(NOT SRC OR NOT DST)
  message(FATAL_ERROR "stage_package.cmake: give -DSRC=<python/rotacal> -DDST=<build/python/rotacal>")
endif()
file(GLOB_RECURSE sources RELATIVE "${SRC}" "${SRC}/*.py" "${SRC}/*.pyi" "${SRC}/py.typed" "${SRC}/data/*.json")
list(FILTER sources EXCLUDE REGEX "(^|/)__pycache__/")
foreach(f IN LISTS sources)
  get_filename_component(folder "${DST}/${f}" DIRECTORY)
  file(COPY "${SRC}/${f}" DESTINATION "${folder}")
endforeach()
file(GLOB_RECURSE staged RELATIVE "${DST}" "${DST}/*.py" "${DST}/*.pyi" "${DST}/data/*.json")
foreach(f IN LISTS staged)
  if(NOT f IN_LIST sources)
    file(REMOVE "${DST}/${f}")
  endif()
endforeach()
