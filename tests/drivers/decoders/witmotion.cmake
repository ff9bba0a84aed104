# WitMotion decoder unit tests (included from tests/drivers/CMakeLists.txt).
posefair_add_test(witmotion_decoder_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/witmotion_decoder_test.cpp
  LIBS posefair::drivers
  LABELS drivers)
