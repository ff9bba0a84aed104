# posefair's CAN layout decoder.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/posefair_can_decoder_test.cpp)
