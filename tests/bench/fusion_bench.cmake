# Orientation estimator updates per second (docs/fusion.md). Run: build/tests/bench/fusion_bench
add_executable(fusion_bench fusion_bench.cpp)
target_link_libraries(fusion_bench PRIVATE posefair::core benchmark::benchmark posefair_warnings)
