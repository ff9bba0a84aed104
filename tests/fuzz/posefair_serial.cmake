# posefair's serial protocol decoder, seeded with sentences and frames (tests/fuzz/corpus/posefair_serial/).
posefair_add_fuzz_target(posefair_serial SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/posefair_serial_fuzz.cpp LIBS posefair::drivers)
