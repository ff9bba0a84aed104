# `posefair bench streams` end to end (the real binary), in cli_tests (CMakeLists.txt here).
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_streams_test.cpp)
# The generated streams themselves (tools/generated_streams.cpp, in posefair_cli), in process.
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/generated_streams_test.cpp)
target_link_libraries(cli_tests PRIVATE posefair_cli)
