# The output encodings' cost per pose and per pose and destination (docs/outputs.md). Run:
# build/tests/bench/output_encoder_bench (with dds: inside tests/dds/in_loopback_netns.sh).
add_executable(output_encoder_bench output_encoder_bench.cpp)
target_link_libraries(output_encoder_bench PRIVATE posefair::service benchmark::benchmark posefair_warnings)
