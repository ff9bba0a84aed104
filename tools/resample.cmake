# posefair resample (docs/splines.md). Included from tools/CMakeLists.txt.
target_sources(posefair_file_commands PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/resample_command.cpp)
posefair_register_command(resample)
