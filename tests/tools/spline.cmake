# `posefair spline` end to end (the real binary).
posefair_add_test(spline_cli_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/spline_command_test.cpp
  LIBS posefair::core posefair::formats GTest::gmock
  LABELS cli)
add_dependencies(spline_cli_tests posefair)
