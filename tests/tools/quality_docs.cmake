# tools/quality_docs.py (regenerates docs/benchmarks.md's results) end to end with the real
# binary and `bench quality --quick`, in cli_tests (CMakeLists.txt here).
target_sources(cli_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/quality_docs_test.cpp)
