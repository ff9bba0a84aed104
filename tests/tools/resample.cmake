# posefair resample end to end (tools/resample_command.cpp), in cli_tests. Included from
# tests/tools/CMakeLists.txt.
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/resample_command_test.cpp)
