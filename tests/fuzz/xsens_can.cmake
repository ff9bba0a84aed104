# The Xsens MTi CAN decoder, seeded with valid frame sequences (tests/fuzz/corpus/xsens_can/).
posefair_add_fuzz_target(xsens_can SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/xsens_can_fuzz.cpp LIBS posefair::drivers)
