# The Xsens MTi CAN output decoder.
posefair_add_test(xsens_can_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/xsens_can_decoder_test.cpp LIBS posefair::drivers LABELS drivers)
