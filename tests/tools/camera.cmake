# `posefair camera` end to end (the real binary).
posefair_add_test(camera_cli_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/camera_command_test.cpp
  LIBS posefair::core GTest::gmock
  LABELS cli)
add_dependencies(camera_cli_tests posefair)
