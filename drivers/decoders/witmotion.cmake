# WitMotion (WT901 family) serial protocol: registry name "witmotion".
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/witmotion_decoder.cpp)
