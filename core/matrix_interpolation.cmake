# Alexa / Hawkins & Grimm linear combination of transformations (docs/matrix-interpolation.md).
target_sources(posefair_core PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/matrix_functions.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/eigen_matrix_functions.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/linear_combination.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/keyframe_weights.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/keyframe_interpolation.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/camera_matrix.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/matrix_interpolation_study.cpp
)
