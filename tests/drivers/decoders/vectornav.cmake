# VectorNav ASCII decoder tests.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/vectornav_decoder_test.cpp)
