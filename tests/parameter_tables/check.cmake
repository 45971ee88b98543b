# cmake -DTOOL=the generator -DTOML=in.toml -DOUT=out.cpp
#       (-DEXPECTED=expected.cpp | -DMESSAGE=regex) -P check.cmake
# EXPECTED: the generator takes TOML and writes EXPECTED to the letter.
# MESSAGE: it refuses TOML (exit 1) with an error matching MESSAGE and writes
# no OUT.
file(REMOVE ${OUT})
execute_process(COMMAND ${TOOL} ${TOML} ${OUT} RESULT_VARIABLE status ERROR_VARIABLE error)
if(DEFINED EXPECTED)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "the generator refused ${TOML} (${status}): ${error}")
  endif()
  file(READ ${OUT} written)
  file(READ ${EXPECTED} expected)
  if(NOT written STREQUAL expected)
    message(FATAL_ERROR "${TOML} gave\n${written}\nnot\n${expected}")
  endif()
else()
  if(NOT status EQUAL 1)
    message(FATAL_ERROR "the generator took ${TOML} (exit ${status}, not 1): ${error}")
  endif()
  if(NOT error MATCHES "${MESSAGE}")
    message(FATAL_ERROR "the generator's error on ${TOML} was\n${error}\nnot\n${MESSAGE}")
  endif()
  if(EXISTS ${OUT})
    message(FATAL_ERROR "the generator wrote ${OUT} from a table it refused")
  endif()
endif()
