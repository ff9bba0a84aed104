# posefair fuse, calibrate, bench fusion and bench gyro-fairing end to end (docs/fusion.md), in cli_tests.
# Included from tests/tools/CMakeLists.txt.
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/fusion_commands_test.cpp)
