# The Xsens MTData2 decoder.
posefair_add_test(xsens_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/xsens_decoder_test.cpp LIBS posefair::drivers LABELS drivers)
