# `posefair camera` (docs/matrix-interpolation.md).
target_sources(posefair_file_commands PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/camera_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/camera_keyframe_file.cpp)
posefair_register_command(camera)
