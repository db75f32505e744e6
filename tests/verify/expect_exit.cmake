# cmake -DCOMMAND="prog;arg;..." -DEXPECTED_EXIT=N -P expect_exit.cmake
# Runs COMMAND and fails unless it exits with status EXPECTED_EXIT exactly.
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
message("${err}")
if(NOT "${status}" STREQUAL "${EXPECTED_EXIT}")
    message(FATAL_ERROR "expected exit status ${EXPECTED_EXIT}, got '${status}'")
endif()
