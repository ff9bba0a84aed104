# `posefair bench quality` and `posefair bench latency` (docs/benchmarks.md).
target_sources(posefair_cli PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_quality_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_latency_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_datasets.cpp)
posefair_register_command(bench)
