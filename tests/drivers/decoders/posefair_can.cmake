# posefair's CAN layout decoder.
posefair_add_test(posefair_can_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/posefair_can_decoder_test.cpp LIBS posefair::drivers LABELS drivers)
