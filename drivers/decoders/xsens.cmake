# Xsens MTi (Xbus MTData2): decoder and frame encoder.
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/xsens_decoder.cpp)
