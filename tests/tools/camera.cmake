# `posefair camera` end to end (the real binary), in cli_tests (CMakeLists.txt here).
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/camera_command_test.cpp)
