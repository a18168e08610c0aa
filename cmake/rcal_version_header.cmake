# SPDX-License-Identifier: MIT
# rcal_version_header.cmake - writes rc_version.h, the generated header that
# carries the version and the compile-time limits of the core (RC_MAX_PARAMS,
# RC_MAX_EFFECTS). It is the one place those values come from: lib/rc_config.h
# includes it, the build puts it in <build>/include and `cmake --install`
# installs it beside the other headers, so a consumer compiles with the values
# the library was built with.
#
# Two uses:
#   include(cmake/rcal_version_header.cmake)            (CMake builds)
#   rcal_write_version_header(<dir>)                    writes <dir>/rc_version.h
#
#   cmake -DRCAL_HEADER_DIR=<dir> [-DRCAL_MAX_PARAMS=n] [-DRCAL_MAX_EFFECTS=n] \
#         -P cmake/rcal_version_header.cmake             (builds without CMake:
#         firmware_host/cross_build.sh, scripts/stack_usage.sh, ...)
set(RCAL_DEFAULT_MAX_PARAMS 96)
set(RCAL_DEFAULT_MAX_EFFECTS 24)
set(_rcal_version_header_dir "${CMAKE_CURRENT_LIST_DIR}")

function(rcal_write_version_header dir)
  foreach(v RCAL_MAX_PARAMS RCAL_MAX_EFFECTS)
    if(NOT DEFINED ${v} OR "${${v}}" STREQUAL "")
      string(REPLACE "RCAL_" "RCAL_DEFAULT_" d ${v})
      set(${v} ${${d}})
    endif()
    if(NOT "${${v}}" MATCHES "^[1-9][0-9]*$")
      message(FATAL_ERROR "${v} must be a positive integer, not '${${v}}'")
    endif()
  endforeach()
  if(NOT DEFINED PROJECT_VERSION OR NOT PROJECT_NAME STREQUAL "rcal")
    # script mode or a foreign project: the version of the top CMakeLists.txt
    file(STRINGS "${_rcal_version_header_dir}/../CMakeLists.txt" _p REGEX "^project\\(rcal VERSION")
    string(REGEX MATCH "VERSION ([0-9]+)\\.([0-9]+)\\.([0-9]+)" _m "${_p}")
    if(NOT _m)
      message(FATAL_ERROR "no 'project(rcal VERSION x.y.z' line in the top CMakeLists.txt")
    endif()
    set(PROJECT_VERSION_MAJOR ${CMAKE_MATCH_1})
    set(PROJECT_VERSION_MINOR ${CMAKE_MATCH_2})
    set(PROJECT_VERSION_PATCH ${CMAKE_MATCH_3})
    set(PROJECT_VERSION "${CMAKE_MATCH_1}.${CMAKE_MATCH_2}.${CMAKE_MATCH_3}")
  endif()
  configure_file("${_rcal_version_header_dir}/../lib/rc_version.h.in" "${dir}/rc_version.h" @ONLY)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
  if(NOT RCAL_HEADER_DIR)
    message(FATAL_ERROR "usage: cmake -DRCAL_HEADER_DIR=<dir> -P ${CMAKE_CURRENT_LIST_FILE}")
  endif()
  rcal_write_version_header("${RCAL_HEADER_DIR}")
endif()
