# Included by ctest (a TEST_INCLUDE_FILES entry of tests/CMakeLists.txt, after the files of the
# discovered GoogleTest cases): COST on the slowest tests, so that `ctest -j` on a clean clone
# (no cost data of its own yet) starts them first instead of in their number order, which put
# the fourteen IndependentDiagnose cases and IndependentSigmaCoverage last and could leave one
# core idle while the other finished a minute-long test.
# FITCAL_DISCOVERED_TESTS: the discovered tests' files (<target>[1]_tests.cmake);
# FITCAL_TEST_COSTS: "regex=cost" pairs, cost in seconds of wall on the 2-core machine (relative
# only; the documented commands' tests carry their own COST in tests/CMakeLists.txt). Parameterised
# cases are matched by a regex because their names carry GetParam()'s bytes, which hold pointers
# and change with every discovery.
foreach(discovered IN LISTS FITCAL_DISCOVERED_TESTS)
  if(NOT EXISTS "${discovered}")
    continue()
  endif()
  file(STRINGS "${discovered}" added REGEX "^add_test\\(\\[=\\[")
  foreach(line IN LISTS added)
    string(REGEX REPLACE "^add_test\\(\\[=\\[([^]]*)\\]=\\].*$" "\\1" name "${line}")
    foreach(pair IN LISTS FITCAL_TEST_COSTS)
      string(REGEX REPLACE "=[0-9.]+$" "" pattern "${pair}")
      string(REGEX REPLACE "^.*=" "" cost "${pair}")
      if(name MATCHES "${pattern}")
        set_tests_properties("${name}" PROPERTIES COST ${cost})
        break()
      endif()
    endforeach()
  endforeach()
endforeach()
