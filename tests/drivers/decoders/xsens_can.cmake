# The Xsens MTi CAN output decoder.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/xsens_can_decoder_test.cpp)
