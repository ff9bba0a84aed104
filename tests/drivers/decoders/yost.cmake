# Yost 3-Space decoder tests.
posefair_add_test(yost_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/yost_decoder_test.cpp
                  LIBS posefair::drivers LABELS drivers)
