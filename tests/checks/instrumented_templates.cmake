# The sanitizer build's instrumented objects must not instantiate the fit's inner loop
# (ctest: instrumented_templates_check, sanitizer build only).
# Run: cmake -DOBJECTS="<a.o>|<b.o>|..." -DNM=<nm> -P tests/checks/instrumented_templates.cmake
#
# Why: templates and inline functions instantiated in two objects are linked once, and the copy
# the linker keeps is the first it meets - in the fitcal binary that is the commands' library.
# When a command file constructed a model itself (tools/optiodom_robots.cc made a DiffDriveModel),
# its instrumented -O1 copies of the model's replay on Ceres Jets (an out-of-line Jet product per
# operation) became the ones every fit ran: the command-line tests under the sanitizers took 30x
# their Release time (a generalise test 47 s against 1.6 s). Models are made in the models
# library (MakeDiffDriveModel, ...) and this check keeps it so: any instrumented object defining
# a weak symbol of a Ceres Jet fails, naming the object and the first such symbol.
cmake_minimum_required(VERSION 3.16)
if(NOT OBJECTS OR NOT NM)
  message(FATAL_ERROR "instrumented_templates.cmake: pass -DOBJECTS=<a.o|b.o|...> -DNM=<nm>")
endif()
string(REPLACE "|" ";" objects "${OBJECTS}")
set(violations 0)
set(checked 0)
# (a target's objects include its precompiled header, which nm cannot read)
list(FILTER objects INCLUDE REGEX "\\.o$")
foreach(object IN LISTS objects)
  execute_process(COMMAND ${NM} -C --defined-only ${object} OUTPUT_VARIABLE symbols
                  RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${object}: nm failed (${status})")
  endif()
  math(EXPR checked "${checked} + 1")
  string(REGEX MATCH "[^\n]* W [^\n]*ceres::Jet<[^\n]*" found "${symbols}")
  if(found)
    math(EXPR violations "${violations} + 1")
    message("${object}: instantiates the fit's Jet code in instrumented code: ${found}")
  endif()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "instrumented_templates.cmake: no object checked")
endif()
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} instrumented object(s) instantiate Jet code; make the model in models/")
endif()
message("${checked} instrumented objects checked: no Jet code")
