# Geometric C^k splines: cost per evaluated sample on R^3, S^3, SO(3) for k = 1, 2, 3 and of the
# live window. Included from tests/bench/CMakeLists.txt. Run: build/tests/bench/geometric_spline_bench
add_executable(geometric_spline_bench geometric_spline_bench.cpp)
target_link_libraries(geometric_spline_bench PRIVATE posefair::core benchmark::benchmark posefair_warnings)
