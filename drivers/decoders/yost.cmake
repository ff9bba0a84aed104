# Yost Labs 3-Space wired binary streaming (tared quaternion with response header): registry name "yost".
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/yost_decoder.cpp)
