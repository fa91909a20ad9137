# Every printf-family call takes its format as a string literal, so that -Wformat (an error under
# FITCAL_WERROR) checks the arguments against it (ctest: format_check).
# Run: cmake -DSOURCE_DIR=<checkout> -P tests/checks/format_check.cmake
#
# A wrapper that took doubles and forwarded its format to snprintf printed an int as garbage
# ("no improvement on the 1488919704 held-out runs: CF 20.0000", issue 42). Text goes through
# StrFormat (odometry/text_format.h, format-checked) or, for a format chosen at run time,
# FormatDouble (one double, the format checked when it runs). Only odometry/text_format.cc
# forwards a format; a call elsewhere whose format is not a literal (or a choice between two
# literals) fails the check with the file and the line.
#
# Lines: at most 100 characters (.clang-format's ColumnLimit; UTF-8 counted as characters), so
# that the code reads whole in a side-by-side diff.
cmake_minimum_required(VERSION 3.16)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "format_check.cmake: pass -DSOURCE_DIR=<checkout>")
endif()

set(FORWARDER odometry/text_format.cc)
set(ws "[ \t\r\n]*")
# The arguments before the format: snprintf (buffer, size), fprintf (stream), printf (none).
set(before_format "(snprintf${ws}\\([^,]*,[^,]*,|fprintf${ws}\\([^,]*,|[^a-z_]printf${ws}\\()")
set(literal_format "${ws}(\"|[A-Za-z_.]+${ws}\\?${ws}\")")

set(kMaxColumns 100)
set(utf8_continuation_bytes "")
foreach(byte RANGE 128 191)
  string(ASCII ${byte} c)
  string(APPEND utf8_continuation_bytes "${c}")
endforeach()

set(violations 0)
file(GLOB_RECURSE sources RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/odometry/*.cc ${SOURCE_DIR}/io/*.cc
     ${SOURCE_DIR}/models/*.cc ${SOURCE_DIR}/fit/*.cc ${SOURCE_DIR}/validation/*.cc
     ${SOURCE_DIR}/diagnosis/*.cc ${SOURCE_DIR}/calibrate/*.cc ${SOURCE_DIR}/sim/*.cc
     ${SOURCE_DIR}/interchange/*.cc ${SOURCE_DIR}/cli/*.cc ${SOURCE_DIR}/pages/*.cc
     ${SOURCE_DIR}/odometry/*.h ${SOURCE_DIR}/pages/*.h
     ${SOURCE_DIR}/io/*.h ${SOURCE_DIR}/models/*.h ${SOURCE_DIR}/fit/*.h ${SOURCE_DIR}/validation/*.h
     ${SOURCE_DIR}/diagnosis/*.h ${SOURCE_DIR}/calibrate/*.h ${SOURCE_DIR}/sim/*.h
     ${SOURCE_DIR}/interchange/*.h ${SOURCE_DIR}/cli/*.h)
foreach(source IN LISTS sources)
  if(source STREQUAL FORWARDER)
    continue()
  endif()
  file(READ ${SOURCE_DIR}/${source} text)
  string(REGEX REPLACE "[][;\\]" "_" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(line_number 0)
  foreach(line IN LISTS lines)
    math(EXPR line_number "${line_number} + 1")
    string(LENGTH "${line}" bytes)
    if(bytes GREATER kMaxColumns)
      string(REGEX REPLACE "[${utf8_continuation_bytes}]" "" characters "${line}")
      string(LENGTH "${characters}" columns)
      if(columns GREATER kMaxColumns)
        message(SEND_ERROR "${source}:${line_number}: ${columns} characters, over ${kMaxColumns}")
        math(EXPR violations "${violations} + 1")
      endif()
    endif()
  endforeach()
  string(REGEX MATCHALL "${before_format}[^,)]*" calls "${text}")
  foreach(call IN LISTS calls)
    string(REGEX REPLACE "^${before_format}" "" format_argument "${call}")
    if(call MATCHES "vs?n?printf" OR NOT format_argument MATCHES "^${literal_format}")
      string(FIND "${text}" "${call}" offset)
      string(SUBSTRING "${text}" 0 ${offset} head)
      string(REGEX MATCHALL "\n" newlines "${head}")
      list(LENGTH newlines line_number)
      math(EXPR line_number "${line_number} + 1")
      message(SEND_ERROR "${source}:${line_number}: a printf-family call whose format is not a "
                         "literal; use StrFormat or FormatDouble (odometry/text_format.h)")
      math(EXPR violations "${violations} + 1")
    endif()
  endforeach()
endforeach()
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} line(s) over ${kMaxColumns} characters or printf-family "
                      "call(s) with a format that is not a literal (tests/checks/format_check.cmake)")
endif()
