# The Xsens MTData2 decoder.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/xsens_decoder_test.cpp)
