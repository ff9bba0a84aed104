# `posefair reproduce lee-shin` (docs/fairing.md, "Section 6 reproduced").
target_sources(posefair_file_commands PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/reproduce_command.cpp)
posefair_register_command(reproduce)
