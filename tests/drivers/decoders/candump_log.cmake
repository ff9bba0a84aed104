# candump log files and their replay through the CAN decoders.
posefair_add_test(candump_log_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/candump_log_test.cpp LIBS posefair::drivers LABELS drivers)
