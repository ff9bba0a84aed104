# resampling_tests: gap bridging and output-rate resampling on the geometric spline.
posefair_add_test(resampling_tests SOURCES resampling_tests.cpp LIBS posefair::core LABELS core)
