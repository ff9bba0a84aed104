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
# eigen_matrix_functions.cpp is Eigen's MatrixFunctions, the reference the tests and the study
# check ours against, and the costliest file to compile (about 50 s; 120 s under ASan+UBSan). It
# compiles on its own, beside the other batches, and without sanitizers: it is Eigen's code, and
# instrumenting it would check Eigen, not posefair.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/src/eigen_matrix_functions.cpp PROPERTIES
  SKIP_UNITY_BUILD_INCLUSION ON SKIP_PRECOMPILE_HEADERS ON)
if(POSEFAIR_SANITIZE_ADDRESS OR POSEFAIR_SANITIZE_THREAD)
  set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/src/eigen_matrix_functions.cpp PROPERTIES
    COMPILE_OPTIONS -fno-sanitize=all)
endif()
