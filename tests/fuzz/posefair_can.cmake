# posefair's CAN layout decoder, seeded with valid frame sequences (tests/fuzz/corpus/posefair_can/).
posefair_add_fuzz_target(posefair_can SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/posefair_can_fuzz.cpp LIBS posefair::drivers)
