# HID decoder, descriptor parser and GPIO edge pairing throughput. Run: build/tests/bench/hid_bench
add_executable(hid_bench ${CMAKE_CURRENT_LIST_DIR}/hid_bench.cpp)
target_link_libraries(hid_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
