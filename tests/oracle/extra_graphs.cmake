# The graphs of the oracle's extra pairs for identify_unambiguous_oracle_test: for each
# WHICH:SEED of PAIRS, `oracle_recall --extra WHICH --seed SEED --budget 0 --keep KEEP` (the
# pair written, cfgen run on it, every witness checked, nothing sampled), kept in
# KEEP/extra_WHICH_seed_SEED. Fails when a run fails or a witness is unsound.
string(REPLACE "," ";" pairs "${PAIRS}")
foreach(p IN LISTS pairs)
  string(REPLACE ":" ";" ws "${p}")
  list(GET ws 0 which)
  list(GET ws 1 seed)
  execute_process(
    COMMAND ${ORACLE_RECALL} --extra ${which} --seed ${seed} --budget 0 --keep ${KEEP}
      --cfgen ${CFGEN} -j 1 --quiet
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "oracle_recall --extra ${which} --seed ${seed} failed (${rc})")
  endif()
endforeach()
