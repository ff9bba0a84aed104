# Hold-out comparison of pose_interpolation = "matrix-lerp" and "spline" on recorded poses with
# position (docs/splines.md, "In the daemon"). Run from the project root:
#   build/tests/bench/pose_interpolation_study [data dir; default $POSEFAIR_DATA, else ../shared/data]
add_executable(pose_interpolation_study ${CMAKE_CURRENT_SOURCE_DIR}/pose_interpolation_study.cpp)
# tools/benchmark_data.hpp: where the full data sets are looked for, and the message when missing.
target_include_directories(pose_interpolation_study PRIVATE ${PROJECT_SOURCE_DIR}/tools)
target_link_libraries(pose_interpolation_study PRIVATE posefair::core posefair::formats posefair_warnings)
