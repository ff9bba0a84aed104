# pose_lerp_tests: Alexa's lerp of the 4x4 rigid transform in the live gap bridge and resampler
# ([stream.spline] pose_interpolation = "matrix-lerp").
posefair_add_test(pose_lerp_tests SOURCES rigid_pose_lerp_tests.cpp LIBS posefair::core LABELS core)
