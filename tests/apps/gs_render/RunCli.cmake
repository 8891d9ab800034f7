# Runs one gs-render command line and checks its exit status and output.
# -DEXE=path -DARGS="a|b|c" (| separates arguments) -DEXPECT=zero|nonzero -DPATTERN=regex
# -DWORKDIR=folder for output files.
string(REPLACE "|" ";" arg_list "${ARGS}")
file(MAKE_DIRECTORY "${WORKDIR}")
execute_process(COMMAND "${EXE}" ${arg_list} WORKING_DIRECTORY "${WORKDIR}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(all "${out}${err}")
if(EXPECT STREQUAL "zero" AND NOT rc EQUAL 0)
  message(FATAL_ERROR "expected exit 0, got ${rc}:\n${all}")
endif()
if(EXPECT STREQUAL "nonzero" AND rc EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0:\n${all}")
endif()
if(NOT all MATCHES "${PATTERN}")
  message(FATAL_ERROR "output does not match '${PATTERN}':\n${all}")
endif()
message(STATUS "exit ${rc}, output matches '${PATTERN}'")
