# `posefair devices` (docs/devices.md).
target_sources(posefair_cli PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/devices_command.cpp)
posefair_register_command(devices)
