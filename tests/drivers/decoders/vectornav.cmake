# VectorNav ASCII decoder tests.
posefair_add_test(vectornav_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/vectornav_decoder_test.cpp
                  LIBS posefair::drivers LABELS drivers)
