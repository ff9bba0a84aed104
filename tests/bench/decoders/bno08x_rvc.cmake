# BNO08x UART-RVC decoder throughput. Included from tests/bench/CMakeLists.txt (which finds
# benchmark). Run: build/tests/bench/bno08x_rvc_bench
add_executable(bno08x_rvc_bench ${CMAKE_CURRENT_LIST_DIR}/bno08x_rvc_bench.cpp)
target_link_libraries(bno08x_rvc_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
