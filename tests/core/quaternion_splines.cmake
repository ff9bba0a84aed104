# Ramamoorthi & Barr quaternion splines: building blocks, gradients, and the paper's reproduction.
posefair_add_test(quaternion_splines_tests
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/quaternion_spline_parts_test.cpp
    ${CMAKE_CURRENT_LIST_DIR}/quaternion_spline_test.cpp
    ${CMAKE_CURRENT_LIST_DIR}/quaternion_spline_reproduction_test.cpp
  LIBS posefair::core GTest::gmock
  LABELS core)
