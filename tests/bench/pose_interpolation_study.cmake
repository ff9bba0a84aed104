# Hold-out comparison of pose_interpolation = "matrix-lerp" and "spline" on recorded poses with
# position (docs/splines.md, "In the daemon"). Run from the project root:
#   build/tests/bench/pose_interpolation_study [../shared/data]
add_executable(pose_interpolation_study ${CMAKE_CURRENT_SOURCE_DIR}/pose_interpolation_study.cpp)
target_link_libraries(pose_interpolation_study PRIVATE posefair::core posefair::formats posefair_warnings)
