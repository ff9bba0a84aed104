# `posefair sub` (docs/protocol.md, "posefair sub").
target_sources(posefair_cli PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/sub_command.cpp)
posefair_register_command(sub)
