# Orientation estimation from raw IMU readings (docs/fusion.md): in core_tests, no program of
# its own (each test program costs a link in three builds).
target_sources(core_tests PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/orientation_estimator_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/estimator_robustness_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/orientation_error_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/magnetometer_calibration_test.cpp)
