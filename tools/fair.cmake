# `posefair fair` (docs/fairing.md).
target_sources(posefair_file_commands PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/fair_command.cpp)
posefair_register_command(fair)
