# Writes a graph with its certificate file, then has the independent checker
# (tests/oracle/oracle_certcheck, no code shared with cfgen) recheck every certificate in it.
# EXTRA: more cfgen options (a list); EXPECT: a regular expression the checker's summary
# must match (e.g. a kind of leaf that must be there).
execute_process(COMMAND ${CFGEN} ${A} ${B} -o ${OUT} --certificates ${CERT} ${EXTRA} --quiet
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cfgen ${A} ${B} --certificates failed with status ${rc}")
endif()
execute_process(COMMAND ${CHECK} ${OUT} ${CERT} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "oracle_certcheck rejected certificates of ${CERT} (status ${rc})")
endif()
if(DEFINED EXPECT AND NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "oracle_certcheck's summary does not match ${EXPECT}")
endif()
