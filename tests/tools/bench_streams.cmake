# `posefair bench streams` end to end (the real binary), in cli_tests (CMakeLists.txt here).
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_streams_test.cpp)
