# `posefair calibrate` (docs/fusion.md): magnetometer calibration, files in and out.
target_sources(posefair_file_commands PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/calibrate_command.cpp)
posefair_register_command(calibrate)
