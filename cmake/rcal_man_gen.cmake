# SPDX-License-Identifier: MIT
# rcal_man_gen.cmake - the manual pages and the bash completion, written at
# build time from the option tables the commands parse with (the same
# tables --help prints), through the program's hidden modes:
#   rcal --help-commands        the command names
#   rcal --help-roff            rcal(1)
#   rcal CMD --help-roff        rcal-CMD(1)
#   rcal --help-bash            the completion script
# Run as: cmake -DRCAL=<program> -DOUT=<dir> -P rcal_man_gen.cmake
# Writes OUT/man1/rcal.1, OUT/man1/rcal-CMD.1 and OUT/bash-completion/rcal.
file(MAKE_DIRECTORY ${OUT}/man1 ${OUT}/bash-completion)
function(rcal_gen file)
  execute_process(COMMAND ${RCAL} ${ARGN} OUTPUT_FILE ${file}.tmp RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "rcal ${ARGN}: exit ${rc}: ${err}")
  endif()
  file(RENAME ${file}.tmp ${file})
endfunction()
execute_process(COMMAND ${RCAL} --help-commands OUTPUT_VARIABLE cmds RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT cmds)
  message(FATAL_ERROR "rcal --help-commands: exit ${rc}")
endif()
string(REGEX REPLACE "\n$" "" cmds "${cmds}")
string(REPLACE "\n" ";" cmds "${cmds}")
rcal_gen(${OUT}/man1/rcal.1 --help-roff)
foreach(c ${cmds})
  rcal_gen(${OUT}/man1/rcal-${c}.1 ${c} --help-roff)
endforeach()
rcal_gen(${OUT}/bash-completion/rcal --help-bash)
