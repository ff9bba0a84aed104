# xsens_can decoding throughput (payload bytes and frames per second). Run: build/tests/bench/xsens_can_bench
add_executable(xsens_can_bench ${CMAKE_CURRENT_LIST_DIR}/xsens_can_bench.cpp)
target_link_libraries(xsens_can_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
