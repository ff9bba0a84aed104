# Ramamoorthi & Barr quaternion splines on the 7-keyframe example. Included from
# tests/bench/CMakeLists.txt. Run: build/tests/bench/quaternion_spline_bench
add_executable(quaternion_spline_bench ${CMAKE_CURRENT_LIST_DIR}/quaternion_spline_bench.cpp)
target_link_libraries(quaternion_spline_bench PRIVATE posefair::core benchmark::benchmark posefair_warnings)
