# Geometric C^k splines (core/geometric_splines.cmake). Included from tests/core/CMakeLists.txt.
posefair_add_test(geometric_splines_tests
  SOURCES
    spline_smoothing_function_test.cpp
    euclidean_geometric_spline_test.cpp
    sphere_geometric_spline_test.cpp
    so3_geometric_spline_test.cpp
    knot_velocity_test.cpp
    pose_spline_test.cpp
  LIBS posefair::core GTest::gmock
  LABELS core)
