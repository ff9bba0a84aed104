# The Xsens MTData2 decoder, seeded with valid messages (tests/fuzz/corpus/xsens/).
posefair_add_fuzz_target(xsens SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/xsens_fuzz.cpp LIBS posefair::drivers)
