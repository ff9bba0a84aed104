# `posefair bench quality` and `posefair bench latency` (docs/benchmarks.md).
target_sources(posefair_cli PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_quality_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_latency_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_datasets.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_scoring.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_configurations.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_tuning.cpp)
posefair_register_command(bench)
