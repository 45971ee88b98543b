# cmake -DSCRIPT=scripts/parameter_table.cmake -DHERE=this folder -DWORK=a folder
# -P check.cmake: good.toml gives good_table.cpp.expected to the letter.
execute_process(COMMAND ${CMAKE_COMMAND} -DTOML=${HERE}/good.toml -DOUT=${WORK}/good_table.cpp
                        -P ${SCRIPT} RESULT_VARIABLE failed)
if(failed)
  message(FATAL_ERROR "parameter_table.cmake refused good.toml")
endif()
file(READ ${WORK}/good_table.cpp written)
file(READ ${HERE}/good_table.cpp.expected expected)
if(NOT written STREQUAL expected)
  message(FATAL_ERROR "good.toml gave\n${written}\nnot\n${expected}")
endif()
