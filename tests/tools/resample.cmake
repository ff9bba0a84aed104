# posefair resample end to end (tools/resample_command.cpp). Included from tests/tools/CMakeLists.txt.
posefair_add_test(resample_cli_tests
  SOURCES resample_command_test.cpp
  LIBS posefair::core posefair::formats GTest::gmock
  LABELS cli)
add_dependencies(resample_cli_tests posefair)
