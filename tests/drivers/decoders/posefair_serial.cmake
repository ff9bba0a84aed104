# posefair's serial protocol decoder.
posefair_add_test(posefair_serial_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/posefair_serial_decoder_test.cpp LIBS posefair::drivers LABELS drivers)
