# The VectorNav ASCII decoder, seeded with the manuals' example sentences and encoded streams.
posefair_add_fuzz_target(vectornav SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/vectornav_fuzz.cpp LIBS posefair::drivers)
