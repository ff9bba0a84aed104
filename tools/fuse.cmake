# `posefair fuse` (docs/fusion.md), and the estimator run and option parsing that
# `posefair bench fusion` shares.
target_sources(posefair_file_commands PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/fuse_command.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/fusion_run.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/estimator_option_text.cpp)
posefair_register_command(fuse)
