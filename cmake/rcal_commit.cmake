# SPDX-License-Identifier: MIT
# rcal_commit.cmake - the commit `rcal --version` names, run as a script at
# every build (tools/CMakeLists.txt, target rcal_commit_id):
#   cmake -DSRC=<source dir> -DOUT=<file.c> -P rcal_commit.cmake
# writes OUT with `const char rcal_commit[] = "<git describe --tags --always
# --dirty --abbrev=12>";`, or "unknown" when SRC is not the top of a git
# checkout (a tarball, a copy, git missing), and rewrites it only when that
# changes: a rebuild at the same commit recompiles nothing. Only the rcal
# program carries it (never an output file: the goldens stay reproducible).
set(_commit unknown)
find_program(_git git)
if(_git)
  execute_process(COMMAND ${_git} -C ${SRC} rev-parse --show-toplevel RESULT_VARIABLE _rc
    OUTPUT_VARIABLE _top OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  get_filename_component(_src_real ${SRC} REALPATH)
  if(_rc EQUAL 0 AND _top)
    get_filename_component(_top ${_top} REALPATH)
  endif()
  if(_rc EQUAL 0 AND _top STREQUAL _src_real)
    execute_process(COMMAND ${_git} -C ${SRC} describe --tags --always --dirty --abbrev=12 RESULT_VARIABLE _rc
      OUTPUT_VARIABLE _d OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(_rc EQUAL 0 AND _d MATCHES "^[A-Za-z0-9._+/-]+$")
      set(_commit ${_d})
    endif()
  endif()
endif()
set(_text "/* written by cmake/rcal_commit.cmake at build time; do not edit */\nconst char rcal_commit[] = \"${_commit}\";\n")
if(EXISTS ${OUT})
  file(READ ${OUT} _old)
else()
  set(_old "")
endif()
if(NOT _old STREQUAL _text)
  file(WRITE ${OUT} "${_text}")
endif()
