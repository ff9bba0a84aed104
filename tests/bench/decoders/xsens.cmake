# Xsens MTData2 decoding throughput. Run: build/tests/bench/xsens_bench
add_executable(xsens_bench ${CMAKE_CURRENT_LIST_DIR}/xsens_bench.cpp)
target_link_libraries(xsens_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
