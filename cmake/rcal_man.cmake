# SPDX-License-Identifier: MIT
# rcal_man.cmake - rcal_man_target(<cmd_*.c ...>): the target rcal_man (part
# of the default build) writes <build>/man/man1/rcal.1, rcal-CMD.1 for every
# tools/cmd_CMD.c, and <build>/man/bash-completion/rcal by running the
# freshly built program (cmake/rcal_man_gen.cmake); installed into
# share/man/man1 and share/bash-completion/completions. Not when
# cross-compiling (the program cannot run here): then nothing is written.
# Sets RCAL_MAN_DIR (<build>/man) in the caller's scope.
function(rcal_man_target)
  set(RCAL_MAN_DIR ${PROJECT_BINARY_DIR}/man PARENT_SCOPE)
  if(CMAKE_CROSSCOMPILING)
    message(STATUS "manual pages and completion: not generated (cross-compiling)")
    return()
  endif()
  set(dir ${PROJECT_BINARY_DIR}/man)
  set(pages ${dir}/man1/rcal.1)
  foreach(src ${ARGN})
    get_filename_component(n ${src} NAME_WE)
    string(REGEX REPLACE "^cmd_" "" n ${n})
    list(APPEND pages ${dir}/man1/rcal-${n}.1)
  endforeach()
  add_custom_command(OUTPUT ${pages} ${dir}/bash-completion/rcal
    COMMAND ${CMAKE_COMMAND} -DRCAL=$<TARGET_FILE:rcal> -DOUT=${dir} -P ${PROJECT_SOURCE_DIR}/cmake/rcal_man_gen.cmake
    DEPENDS rcal ${PROJECT_SOURCE_DIR}/cmake/rcal_man_gen.cmake
    COMMENT "manual pages and bash completion from the option tables" VERBATIM)
  add_custom_target(rcal_man ALL DEPENDS ${pages} ${dir}/bash-completion/rcal)
  install(FILES ${pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  install(FILES ${dir}/bash-completion/rcal DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
endfunction()
