# Regenerates a graph and compares it with the bundled golden file.
execute_process(COMMAND ${CFGEN} ${A} ${B} -o ${OUT} --quiet RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cfgen ${A} ${B} failed with status ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT} ${GOLDEN} RESULT_VARIABLE diff)
if(NOT diff EQUAL 0)
  message(FATAL_ERROR "${OUT} differs from the golden file ${GOLDEN}: regenerate it with "
                      "bash scripts/setup.sh if the change is intended")
endif()
