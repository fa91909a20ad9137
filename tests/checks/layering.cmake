# The layering of fitcal's libraries, checked on every include (ctest: layering_check).
# Run: cmake -DSOURCE_DIR=<checkout> -P tests/checks/layering.cmake
#
# Each folder is a layer and may include only its own layer and the ones below it:
#   odometry (0)  replay, poses, encoder samples, the robot description
#   io (1)        file formats, data sets, atomic writes
#   pages (2)     the pages and their renderers: the report's model, HTML, SVG, Markdown, JSON, CSV
#   models (3)    the kinematic models behind one seam, each reading its own robot YAML through io
#   sim (4)       the simulators that write data sets, driving the models through the seam
#   fit (5)       residuals, costs, fitters, the split into training and held-out runs
#   validation (6) held-out judgement, metrics, statistics
#   diagnosis (7) what the residual left after a fit says
#   calibrate (8) one calibration from a request: candidates, choices by transfer, the gate, the
#                 held-out judgements, the record to write
#   interchange (9) the formats and tools of other ecosystems: ROS 2 (a bag cut into runs,
#                 controller parameters exported, replayed and their covariance), OptiOdom
#   cli (10)      the commands: load, one library call, print
# A new include against this order fails the check with the file, the line and the layers.
cmake_minimum_required(VERSION 3.16)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "layering.cmake: pass -DSOURCE_DIR=<checkout>")
endif()

set(LAYERS odometry io pages models sim fit validation diagnosis calibrate interchange cli)
# No exception: a model that reads files of its own (ASOC's encoder files, models/asoc/asoc_files.h)
# hands the data-set loader a reader through its Robot (Robot::read_own_encoder_file).
set(ALLOWED_EXCEPTIONS "")

set(violations 0)
foreach(layer IN LISTS LAYERS)
  list(FIND LAYERS ${layer} rank)
  file(GLOB_RECURSE sources RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/${layer}/*.h ${SOURCE_DIR}/${layer}/*.cc)
  foreach(source IN LISTS sources)
    # One list element per line: semicolons and brackets would split or join CMake list elements.
    file(READ ${SOURCE_DIR}/${source} text)
    string(REGEX REPLACE "[][;\\]" "_" text "${text}")
    string(REPLACE "\n" ";" lines "${text}")
    set(line_number 0)
    foreach(line IN LISTS lines)
      math(EXPR line_number "${line_number} + 1")
      if(line MATCHES "^#include \"([a-z0-9_]+)/([^\"]+)\"")
        set(target_layer ${CMAKE_MATCH_1})
        set(included "${CMAKE_MATCH_1}/${CMAKE_MATCH_2}")
        list(FIND LAYERS ${target_layer} target_rank)
        if(target_rank GREATER rank AND NOT "${source} -> ${included}" IN_LIST ALLOWED_EXCEPTIONS)
          message(SEND_ERROR "${source}:${line_number}: includes ${included}: layer "
                             "'${layer}' may not depend on '${target_layer}' (above it)")
          math(EXPR violations "${violations} + 1")
        endif()
      endif()
    endforeach()
  endforeach()
endforeach()
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} include(s) against the layering (tests/checks/layering.cmake)")
endif()
