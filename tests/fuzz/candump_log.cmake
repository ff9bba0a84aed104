# The candump log parser, seeded with logs (tests/fuzz/corpus/candump_log/).
posefair_add_fuzz_target(candump_log SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/candump_log_fuzz.cpp LIBS posefair::formats)
