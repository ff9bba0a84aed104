# The Yost 3-Space decoder, seeded with streamed packets (default header, all header fields, rollover).
posefair_add_fuzz_target(yost SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/yost_fuzz.cpp LIBS posefair::drivers)
