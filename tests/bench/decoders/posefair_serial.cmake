# posefair serial protocol decoding throughput. Run: build/tests/bench/posefair_serial_bench
add_executable(posefair_serial_bench ${CMAKE_CURRENT_LIST_DIR}/posefair_serial_bench.cpp)
target_link_libraries(posefair_serial_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
