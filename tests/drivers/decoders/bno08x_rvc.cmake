# BNO08x UART-RVC decoder unit tests (included from tests/drivers/CMakeLists.txt).
posefair_add_test(bno08x_rvc_decoder_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/bno08x_rvc_decoder_test.cpp
  LIBS posefair::drivers
  LABELS drivers)
