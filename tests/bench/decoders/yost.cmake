# Yost 3-Space decoder throughput. Included from tests/bench/CMakeLists.txt (which finds
# benchmark). Run: build/tests/bench/yost_bench
add_executable(yost_bench ${CMAKE_CURRENT_LIST_DIR}/yost_bench.cpp)
target_link_libraries(yost_bench PRIVATE benchmark::benchmark posefair::drivers posefair_warnings)
