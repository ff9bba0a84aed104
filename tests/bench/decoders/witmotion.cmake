# WitMotion decoder throughput. Included from tests/bench/CMakeLists.txt (which finds benchmark).
# Run: build/tests/bench/witmotion_bench
add_executable(witmotion_bench ${CMAKE_CURRENT_LIST_DIR}/witmotion_bench.cpp)
target_link_libraries(witmotion_bench PRIVATE posefair::drivers benchmark::benchmark posefair_warnings)
