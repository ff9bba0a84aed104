# BNO080/BNO085/BNO086 UART-RVC mode: registry name "bno08x-rvc".
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/bno08x_rvc_decoder.cpp)
