# Orientation estimation from raw gyroscope, accelerometer and magnetometer readings (issue 17,
# docs/fusion.md): the estimator interface and registry, VQF, Madgwick and Mahony, magnetometer
# calibration and BROAD's error measures. Included from core/CMakeLists.txt.
target_sources(posefair_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/orientation_estimator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/estimator_registry.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/vqf_estimator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/madgwick_estimator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/mahony_estimator.cpp
)
target_sources(posefair_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/orientation_error.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/magnetometer_calibration.cpp
)
