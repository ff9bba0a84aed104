# posefair_can decoding throughput (payload bytes and frames per second). Run: build/tests/bench/posefair_can_bench
add_executable(posefair_can_bench ${CMAKE_CURRENT_LIST_DIR}/posefair_can_bench.cpp)
target_link_libraries(posefair_can_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
