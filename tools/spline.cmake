# `posefair spline` (docs/quaternion-splines.md).
target_sources(posefair_file_commands PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/spline_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/keyframe_file.cpp)
posefair_register_command(spline)
