# BNO08x UART-RVC decoder, seeded with frame streams (tests/fuzz/corpus/bno08x_rvc/).
posefair_add_fuzz_target(bno08x_rvc SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/bno08x_rvc_fuzz.cpp LIBS posefair::drivers)
