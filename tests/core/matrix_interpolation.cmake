# Matrix exp/log/sqrt, Alexa's operators, keyframe weights, cameras, Section 4.2/5.1 studies.
posefair_add_test(matrix_interpolation_tests
  SOURCES
    ${CMAKE_CURRENT_SOURCE_DIR}/matrix_functions_test.cpp
    ${CMAKE_CURRENT_SOURCE_DIR}/linear_combination_test.cpp
    ${CMAKE_CURRENT_SOURCE_DIR}/keyframe_weights_test.cpp
    ${CMAKE_CURRENT_SOURCE_DIR}/camera_matrix_test.cpp
    ${CMAKE_CURRENT_SOURCE_DIR}/matrix_interpolation_study_test.cpp
  LIBS posefair::core GTest::gmock
  LABELS core)
