# Live resampling and gap bridging: cost and added delay. Run: build/tests/bench/resampling_bench
add_executable(resampling_bench resampling_bench.cpp)
target_link_libraries(resampling_bench PRIVATE posefair::core benchmark::benchmark posefair_warnings)
