# Ramamoorthi & Barr quaternion splines (docs/quaternion-splines.md): cubic Hermite curves in
# R⁴, the covariant-acceleration objective, NLopt minimisation, Euler–Lagrange refinement.
find_package(NLopt REQUIRED)
target_sources(posefair_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/gauss_legendre_rule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/hermite_curve4.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/covariant_acceleration.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/quaternion_spline_objective.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/quaternion_spline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/quaternion_spline_study.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/sampled_rotation_energy.cpp
)
target_link_libraries(posefair_core PUBLIC NLopt::nlopt)
