# `posefair bench quality`, `posefair bench streams`, `posefair bench latency`, `posefair bench fusion` and `posefair bench gyro-fairing` (docs/benchmarks.md).
target_sources(posefair_cli PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_quality_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_streams_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/generated_streams.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_latency_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_fusion_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/bench_gyro_fairing_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_datasets.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_scoring.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_configurations.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/quality_tuning.cpp)
find_package(nlohmann_json REQUIRED)  # BROAD's trials.json (bench fusion)
target_link_libraries(posefair_cli PRIVATE nlohmann_json::nlohmann_json)
posefair_register_command(bench)
