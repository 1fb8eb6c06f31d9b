# run(<command> <args>...): runs a step of an install test and stops the test with its output when
# it fails; leaves what it printed in run_output (stdout and stderr) and run_stdout (stdout alone).
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed: ${ARGN}\n${out}\n${err}")
  endif()
  set(run_output "${out}${err}" PARENT_SCOPE)
  set(run_stdout "${out}" PARENT_SCOPE)
endfunction()
