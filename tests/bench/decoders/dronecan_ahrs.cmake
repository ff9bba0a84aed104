# dronecan_ahrs decoding throughput (payload bytes and frames per second). Run: build/tests/bench/dronecan_ahrs_bench
add_executable(dronecan_ahrs_bench ${CMAKE_CURRENT_LIST_DIR}/dronecan_ahrs_bench.cpp)
target_link_libraries(dronecan_ahrs_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
