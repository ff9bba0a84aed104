# VectorNav ASCII asynchronous outputs ($VNQMR, $VNYMR, $VNQTN, $VNYPR): registry name "vectornav".
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/vectornav_decoder.cpp)
