# `posefair ctl` (docs/operations.md, "Control socket"). Replies are JSON, read with nlohmann/json
# (Debian 12: nlohmann-json3-dev, header only) for the human tables.
find_package(nlohmann_json 3 REQUIRED)
target_sources(posefair_cli PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/ctl_command.cpp)
target_link_libraries(posefair_cli PRIVATE nlohmann_json::nlohmann_json)
posefair_register_command(ctl)
