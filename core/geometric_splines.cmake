# Geometric C^k splines of Rodrigues, Silva Leite & Jakubiak on R^n, S^2/S^3 and SO(3)
# (docs/splines.md). Included from core/CMakeLists.txt.
target_sources(posefair_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/spline_smoothing_function.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/euclidean_geometric_spline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/sphere_geometric_spline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/so3_geometric_spline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/knot_velocity.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/pose_spline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/pose_spline_window.cpp)
