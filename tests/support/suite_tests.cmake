# Registers one ctest test per GoogleTest suite of a test executable (run at build time, as
# gtest_discover_tests does per test): the tests of a suite then share one process, and with it
# the outputs their SetUpTestSuite makes once. The sanitizer sample takes this form, where one
# process per test made those outputs again for every test, ten times slower than in release.
#   cmake -D EXE=... -D OUT=... -D WORKDIR=... [-D SKIP=Suite.Test:...] -P suite_tests.cmake
# SKIP: tests left out of every suite's filter.
execute_process(COMMAND "${EXE}" --gtest_list_tests OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc})")
endif()
set(negative "")
if(SKIP)
  set(negative ":-${SKIP}")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(script "")
set(suite "")
foreach(line IN LISTS lines)
  if(line MATCHES "^([^ ][^ ]*)\\.( |$)")
    set(suite "${CMAKE_MATCH_1}")
    set(count_${suite} 0)
    list(APPEND suites "${suite}")
  elseif(suite AND line MATCHES "^  [^ ]")
    math(EXPR count_${suite} "${count_${suite}} + 1")
  endif()
endforeach()
foreach(suite IN LISTS suites)
  string(APPEND script "add_test([==[${suite}]==] [==[${EXE}]==] [==[--gtest_filter=${suite}.*${negative}]==])\n"
         "set_tests_properties([==[${suite}]==] PROPERTIES LABELS quick TIMEOUT 900 COST ${count_${suite}}"
         " WORKING_DIRECTORY [==[${WORKDIR}]==])\n")
endforeach()
file(WRITE "${OUT}" "${script}")
