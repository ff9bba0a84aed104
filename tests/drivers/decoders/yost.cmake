# Yost 3-Space decoder tests.
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/yost_decoder_test.cpp)
