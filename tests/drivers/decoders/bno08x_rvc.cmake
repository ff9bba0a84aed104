# BNO08x UART-RVC decoder unit tests (included from tests/drivers/CMakeLists.txt).
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/bno08x_rvc_decoder_test.cpp)
