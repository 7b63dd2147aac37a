# Runs the first test case of a GoogleTest binary: cmake -DEXE=path -P run_first_case.cmake.
# A sanitizer build runs this sample of each slow binary instead of all its cases.
execute_process(COMMAND ${EXE} --gtest_list_tests OUTPUT_VARIABLE list RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed: ${rc}")
endif()
string(REGEX MATCH "([^\n]+\\.)[^\n]*\n  ([^ \n]+)" first "${list}")
if(NOT first)
  message(FATAL_ERROR "${EXE} lists no test case")
endif()
execute_process(COMMAND ${EXE} --gtest_filter=${CMAKE_MATCH_1}${CMAKE_MATCH_2} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "${EXE} --gtest_filter=${CMAKE_MATCH_1}${CMAKE_MATCH_2} failed: ${rc}")
endif()
