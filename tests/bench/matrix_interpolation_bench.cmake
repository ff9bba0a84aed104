# Matrix exp/log/sqrt and one lerp: Hawkins & Grimm's iterations vs Eigen's MatrixFunctions.
# Included from tests/bench/CMakeLists.txt. Run: build/tests/bench/matrix_interpolation_bench
add_executable(matrix_interpolation_bench ${CMAKE_CURRENT_SOURCE_DIR}/matrix_interpolation_bench.cpp)
target_link_libraries(matrix_interpolation_bench PRIVATE posefair::core benchmark::benchmark posefair_warnings)
