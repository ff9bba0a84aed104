# posefair's serial protocol decoder.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/posefair_serial_decoder_test.cpp)
