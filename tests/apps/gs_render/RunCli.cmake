# Runs one command line and checks its exit status and output (gs-render's, gs-convert's and
# gs-bench's checks share it).
# -DEXE=path -DARGS="a|b|c" (| separates arguments) -DEXPECT=zero|nonzero -DPATTERN=regex
# -DWORKDIR=folder for output files, emptied first.
# -DABSENT=regex (optional): the output must not match it (work that should not have started).
# -DFILES="a.png|b.png" (optional): exactly these files must be in WORKDIR afterwards, hidden
# ones included ("none": nothing, e.g. a refused run must not leave a partial output).
string(REPLACE "|" ";" arg_list "${ARGS}")
file(REMOVE_RECURSE "${WORKDIR}")
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
if(DEFINED ABSENT AND all MATCHES "${ABSENT}")
  message(FATAL_ERROR "output matches '${ABSENT}', which it must not:\n${all}")
endif()
if(DEFINED FILES)
  file(GLOB found LIST_DIRECTORIES true RELATIVE "${WORKDIR}" "${WORKDIR}/*" "${WORKDIR}/.*")
  list(REMOVE_DUPLICATES found)
  list(REMOVE_ITEM found "." "..")
  list(SORT found)
  string(REPLACE "|" ";" expected "${FILES}")
  if(FILES STREQUAL "none")
    set(expected "")
  endif()
  list(SORT expected)
  if(NOT "${found}" STREQUAL "${expected}")
    message(FATAL_ERROR "expected the files '${expected}' in ${WORKDIR}, found '${found}':\n${all}")
  endif()
endif()
message(STATUS "exit ${rc}, output matches '${PATTERN}'")
