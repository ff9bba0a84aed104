# VectorNav ASCII decoder throughput. Included from tests/bench/CMakeLists.txt (which finds
# benchmark). Run: build/tests/bench/vectornav_bench
add_executable(vectornav_bench ${CMAKE_CURRENT_LIST_DIR}/vectornav_bench.cpp)
target_link_libraries(vectornav_bench PRIVATE benchmark::benchmark posefair::drivers posefair_warnings)
